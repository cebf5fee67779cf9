"""Robot model and batched forward kinematics against yourdfpy."""

import shutil
from pathlib import Path

import numpy as np
import pytest
import yourdfpy

from ompl_balance.collision.kinematics import RobotModel
from ompl_balance.collision.robots import PANDA_VAMP_DIR as PANDA_VAMP

ROBOTS = Path(__file__).resolve().parent / "robots"


def load_arm3():
    return RobotModel.from_urdf(ROBOTS / "arm3.urdf", ROBOTS / "arm3.srdf", package_map={"testbot": str(ROBOTS)})


def assert_fk_matches_yourdfpy(robot, urdf_path, root, count=40, seed=0):
    urdf = yourdfpy.URDF.load(str(urdf_path), load_meshes=False, build_collision_scene_graph=False)
    q = np.random.default_rng(seed).uniform(robot.lower, robot.upper, size=(count, robot.dof))
    poses = robot.fk(q)
    assert poses.shape == (count, len(robot.link_names), 4, 4)
    for i in range(count):
        urdf.update_cfg(dict(zip(robot.joint_names, q[i])))
        single = robot.fk(q[i])[0]  # one configuration takes its own path (2-D products)
        for k, link in enumerate(robot.link_names):
            np.testing.assert_allclose(poses[i, k], urdf.get_transform(link, root), atol=1e-9, rtol=0)
            np.testing.assert_allclose(single[k], urdf.get_transform(link, root), atol=1e-9, rtol=0)


def test_arm3_model():
    robot = load_arm3()
    assert robot.joint_names == ["turn", "shoulder", "slide"]  # the mimic finger is not a joint of the space
    np.testing.assert_allclose(robot.lower, [-np.pi, -2.6, 0.0])
    np.testing.assert_allclose(robot.upper, [np.pi, 2.6, 0.2])
    assert robot.body_count == 5  # root, three active joints, the mimic joint; fixed flange and tool folded in
    names = [(robot.geometries[a].link, robot.geometries[b].link) for a, b in robot.self_collision_pairs]
    # base-boom disabled by the SRDF; adjacent bodies and the rigid slider/flange/tool group skipped
    assert set(names) == {
        ("base", "slider"),
        ("base", "tool"),
        ("base", "finger"),
        ("column", "slider"),
        ("column", "tool"),
        ("column", "finger"),
        ("boom", "finger"),
    }


def test_fk_matches_yourdfpy_arm3():
    assert_fk_matches_yourdfpy(load_arm3(), ROBOTS / "arm3.urdf", "base")


def test_fk_single_configuration_and_batch_agree():
    robot = load_arm3()
    q = np.random.default_rng(3).uniform(robot.lower, robot.upper, size=(7, robot.dof))
    np.testing.assert_allclose(robot.fk(q)[2], robot.fk(q[2])[0], atol=1e-12, rtol=0)


def test_fk_matches_yourdfpy_panda_vamp():
    robot = RobotModel.from_urdf(PANDA_VAMP / "panda.urdf", PANDA_VAMP / "panda.srdf")
    assert robot.dof == 7 and len(robot.geometries) == 11
    assert_fk_matches_yourdfpy(robot, PANDA_VAMP / "panda.urdf", "panda_link0")


def test_fk_matches_yourdfpy_example_robot_data_panda():
    robots = pytest.importorskip("ompl_balance.collision.robots")
    try:
        robot = robots.load_example_robot_data_panda()
    except ImportError as error:
        pytest.skip(str(error))
    assert robot.joint_names[-1] == "panda_finger_joint1" and robot.dof == 8  # finger_joint2 mimics it
    urdf = robots.example_robot_data_dir() / "robots" / "panda_description" / "urdf" / "panda.urdf"
    assert_fk_matches_yourdfpy(robot, urdf, "panda_link0", count=20)


def test_package_resolved_from_parent_folder_named_like_the_package(tmp_path):
    package = tmp_path / "testbot"
    shutil.copytree(ROBOTS, package)
    robot = RobotModel.from_urdf(package / "arm3.urdf")  # no package map: folder name matches
    assert sum(g.source is not None for g in robot.geometries) == 2


def test_missing_mesh_names_file_and_link(tmp_path):
    shutil.copy(ROBOTS / "arm3.urdf", tmp_path / "arm3.urdf")
    with pytest.raises(FileNotFoundError, match=r"link 'boom'.*package://testbot/meshes/cone.obj"):
        RobotModel.from_urdf(tmp_path / "arm3.urdf")


def test_unreadable_mesh_names_file_and_link(tmp_path):
    shutil.copy(ROBOTS / "arm3.urdf", tmp_path / "arm3.urdf")
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "cone.obj").write_text("this is not a mesh\n")
    with pytest.raises((ValueError, FileNotFoundError), match=r"link '(boom|slider)'"):
        RobotModel.from_urdf(tmp_path / "arm3.urdf", package_map={"testbot": str(tmp_path)})


def test_urdf_that_does_not_parse(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'><parent link='a'/>")
    with pytest.raises(ValueError, match=r"bad\.urdf"):
        RobotModel.from_urdf(bad)
    with pytest.raises(FileNotFoundError, match=r"nowhere\.urdf"):
        RobotModel.from_urdf(tmp_path / "nowhere.urdf")


def test_srdf_naming_unknown_link(tmp_path):
    srdf = tmp_path / "x.srdf"
    srdf.write_text('<robot name="arm3"><disable_collisions link1="base" link2="wing"/></robot>')
    with pytest.raises(ValueError, match="wing"):
        RobotModel.from_urdf(ROBOTS / "arm3.urdf", srdf, package_map={"testbot": str(ROBOTS)})


def test_bad_configurations():
    robot = load_arm3()
    with pytest.raises(ValueError, match="'shoulder'"):
        robot.fk([[0.0, np.nan, 0.1]])
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        robot.fk(np.zeros((2, 4)))


LINKS_AB = '<link name="a"/><link name="b"/>'
REVOLUTE = '<parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'


@pytest.mark.parametrize(
    "body, message",
    [
        (f'{LINKS_AB}\n<joint type="revolute">{REVOLUTE}</joint>', r"line 2: <joint> has no 'name' attribute"),
        (
            '<link name="a"/>\n<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>',
            r"line 2: <joint name='j'> names child link 'b', not a <link> of the file",
        ),
        (
            f'{LINKS_AB}\n<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>',
            r"line 2: joint 'j' \(revolute\) has no <limit lower=\.\.\. upper=\.\.\.>",
        ),
        (
            f'{LINKS_AB}\n<joint name="j" type="prismatic"><parent link="a"/><child link="b"/>\n<limit upper="1"/></joint>',
            r"line 3: joint 'j': <limit> has no 'lower' attribute",
        ),
        (
            f'{LINKS_AB}\n<joint name="j" type="revolute"><child link="b"/></joint>',
            r"line 2: <joint name='j'> has no <parent link=\.\.\.>",
        ),
        (
            f'{LINKS_AB}\n<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
            '<limit lower="low" upper="1"/></joint>',
            r"line 2: joint 'j': <limit lower='low'> must be a number",
        ),
        ('<link name="a"/>\n<link/>', r"line 2: <link> has no 'name' attribute"),
        (
            '<link name="a">\n<collision><geometry><cylinder radius="0.1"/></geometry></collision></link>',
            r"line 2: link 'a': <cylinder> has no 'length' attribute",
        ),
        (
            '<link name="a"><collision><geometry>\n<mesh/></geometry></collision></link>',
            r"line 2: link 'a': <mesh> has no 'filename' attribute",
        ),
        (
            f'{LINKS_AB}<link name="c"/>\n<joint name="j" type="fixed"><parent link="a"/><child link="c"/></joint>'
            '\n<joint name="k" type="fixed"><parent link="b"/><child link="c"/></joint>',
            r"line 3: link 'c' is the child of two joints \('j' and 'k'\)",
        ),
        (
            f'{LINKS_AB}\n<joint name="j" type="floating"><parent link="a"/><child link="b"/></joint>',
            r"line 2: <joint name='j'> has type 'floating'; supported: fixed, revolute, continuous, prismatic",
        ),
        (
            f'{LINKS_AB}\n<joint name="j" type="revolute">{REVOLUTE}<mimic joint="elbow"/></joint>',
            r"line 2: <joint name='j'> mimics joint 'elbow', not a <joint> of the file",
        ),
    ],
)
def test_malformed_urdf_says_what_and_where(tmp_path, body, message):
    path = tmp_path / "broken.urdf"
    path.write_text(f'<robot name="broken">{body}</robot>\n')
    with pytest.raises(ValueError, match=rf"URDF .*broken\.urdf, {message}"):
        RobotModel.from_urdf(path)
