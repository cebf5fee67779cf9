"""Ready-made robots: example-robot-data's Panda and VAMP's Panda (the MotionBenchMaker model)."""

from __future__ import annotations

from importlib import metadata, resources
from pathlib import Path

from .kinematics import RobotModel


def example_robot_data_dir() -> Path:
    """The ``share/example-robot-data`` folder of the installed ``example-robot-data`` wheel.

    The wheel is a cmeel package: no Python module, its files live under
    ``site-packages/cmeel.prefix/share/example-robot-data``.
    """
    try:
        distribution = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError as error:
        raise ImportError("example-robot-data is not installed: pip install 'ompl-balance[robots]'") from error
    share = Path(str(distribution.locate_file("cmeel.prefix/share/example-robot-data")))
    if not share.is_dir():
        raise FileNotFoundError(f"example-robot-data is installed but {share} is missing")
    return share


def load_example_robot_data_panda() -> RobotModel:
    """Franka Panda from example-robot-data (URDF + SRDF, STL collision meshes, box fingers).

    8 active joints: ``panda_joint1..7`` and ``panda_finger_joint1`` (metres, 0..0.04;
    ``panda_finger_joint2`` mimics it). This is not the model of the MotionBenchMaker
    problems; use :func:`load_panda_vamp` for those.
    """
    share = example_robot_data_dir()
    description = share / "robots" / "panda_description"
    return RobotModel.from_urdf(
        description / "urdf" / "panda.urdf",
        description / "srdf" / "panda.srdf",
        package_map={"example-robot-data": str(share)},
    )


#: VAMP's Panda as shipped with the package (URDF, SRDF, collision meshes; Apache-2.0).
PANDA_VAMP_DIR = Path(str(resources.files("ompl_balance") / "data" / "panda_vamp"))


def load_panda_vamp(directory: str | Path | None = None) -> RobotModel:
    """VAMP's Panda, the model the MotionBenchMaker problems were made for.

    By default the copy shipped with the package (:data:`PANDA_VAMP_DIR`); ``directory``
    may name another folder of the same layout: ``panda.urdf``, ``panda.srdf`` and
    ``meshes/collision/*.obj``, as in VAMP's ``resources/panda``. The fingers are fixed
    open at 0.065 m, so 7 joints.
    """
    directory = PANDA_VAMP_DIR if directory is None else Path(directory)
    return RobotModel.from_urdf(directory / "panda.urdf", directory / "panda.srdf")
