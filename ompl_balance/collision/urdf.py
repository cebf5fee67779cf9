"""Structural checks of a URDF file before it is loaded, with errors that say what and where.

:func:`check_urdf` reads the file with Python's expat parser (which knows line numbers)
and raises ``ValueError`` naming the file, the line, the element and what is wrong or
missing: a link or joint without a name, a joint whose ``<parent>``/``<child>`` names a
link the file does not have, a revolute or prismatic joint without ``<limit lower upper>``,
numbers that are not numbers, a collision geometry without its sizes, a kinematic
structure that is not one tree. The loader (:meth:`~ompl_balance.collision.kinematics.RobotModel.from_urdf`)
runs it first, so a broken file never reaches yourdfpy, whose messages for the same
mistakes are bare key names (``'name'``) or ``NoneType`` attribute errors.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn
from xml.parsers import expat

#: Joint types the robot layer moves or folds (``planar`` and ``floating`` are not supported).
JOINT_TYPES = ("fixed", "revolute", "continuous", "prismatic")


@dataclass
class _Node:
    """An XML element with the line it starts on."""

    tag: str
    attributes: dict[str, str]
    line: int
    children: list[_Node] = field(default_factory=list)

    def find(self, tag: str) -> _Node | None:
        return next((c for c in self.children if c.tag == tag), None)

    def describe(self) -> str:
        name = self.attributes.get("name")
        return f"<{self.tag} name={name!r}>" if name is not None else f"<{self.tag}>"


def _read(path: Path) -> _Node:
    parser = expat.ParserCreate()
    stack: list[_Node] = []
    roots: list[_Node] = []

    def start(tag: str, attributes: dict[str, str]) -> None:
        node = _Node(tag, attributes, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(node)
        stack.append(node)

    def end(_tag: str) -> None:
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        with open(path, "rb") as file:
            parser.ParseFile(file)
    except expat.ExpatError as error:
        raise ValueError(f"cannot parse URDF {path}: {error}") from error
    return roots[0]


class _Problems:
    """Raises the first problem found, with the file and line."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, node: _Node, message: str) -> NoReturn:
        raise ValueError(f"URDF {self.path}, line {node.line}: {message}")

    def register(self, named: dict[str, _Node], node: _Node) -> str:
        """Add ``node`` (a <link> or <joint>) to ``named`` under its name; returns the name."""
        name = node.attributes.get("name")
        if not name:
            self.fail(node, f"<{node.tag}> has no 'name' attribute")
        if name in named:
            self.fail(node, f"{node.tag} {name!r} is defined twice (first on line {named[name].line})")
        named[name] = node
        return name

    def numbers(self, owner: str, node: _Node, attribute: str, count: int, required: bool = True) -> list[float] | None:
        """The ``count`` numbers of ``node``'s ``attribute`` (``owner``: the link or joint, for
        messages); ``None`` when absent and not required."""
        text = node.attributes.get(attribute)
        if text is None:
            if required:
                self.fail(node, f"{owner}: <{node.tag}> has no {attribute!r} attribute")
            return None
        try:
            values = [float(v) for v in text.split()]
        except ValueError:
            values = []
        if len(values) != count:
            expected = "a number" if count == 1 else f"{count} numbers"
            self.fail(node, f"{owner}: <{node.tag} {attribute}={text!r}> must be {expected}")
        return values


def check_urdf(path: str | Path) -> None:
    """Raise ``ValueError`` (file, line, element, what is wrong) if ``path`` is not a URDF the
    robot layer can load; return quietly otherwise. ``FileNotFoundError`` if it does not exist."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"URDF file not found: {path}")
    robot = _read(path)
    problems = _Problems(path)
    if robot.tag != "robot":
        problems.fail(robot, f"the root element is <{robot.tag}>, expected <robot name=...>")
    if "name" not in robot.attributes:
        problems.fail(robot, "<robot> has no 'name' attribute")
    links: dict[str, _Node] = {}
    for link in (c for c in robot.children if c.tag == "link"):
        problems.register(links, link)
        for collision in (c for c in link.children if c.tag == "collision"):
            _check_collision(problems, link, collision)
    if not links:
        problems.fail(robot, "<robot> has no <link>")
    joints: dict[str, _Node] = {}
    parent_of: dict[str, str] = {}
    for joint in (c for c in robot.children if c.tag == "joint"):
        name = problems.register(joints, joint)
        kind = joint.attributes.get("type")
        if kind not in JOINT_TYPES:
            problems.fail(joint, f"{joint.describe()} has type {kind!r}; supported: {', '.join(JOINT_TYPES)}")
        ends = {}
        for end in ("parent", "child"):
            element = joint.find(end)
            if element is None or not element.attributes.get("link"):
                problems.fail(joint, f"{joint.describe()} has no <{end} link=...>")
            elif element.attributes["link"] not in links:
                problems.fail(
                    element,
                    f"{joint.describe()} names {end} link {element.attributes['link']!r}, not a <link> of the file",
                )
            else:
                ends[end] = element.attributes["link"]
        child = ends["child"]
        if child in parent_of:
            problems.fail(joint, f"link {child!r} is the child of two joints ({parent_of[child]!r} and {name!r})")
        parent_of[child] = name
        owner = f"joint {name!r}"
        origin = joint.find("origin")
        if origin is not None:
            problems.numbers(owner, origin, "xyz", 3, required=False)
            problems.numbers(owner, origin, "rpy", 3, required=False)
        if kind in ("revolute", "continuous", "prismatic"):
            axis = joint.find("axis")
            if axis is not None:
                xyz = problems.numbers(owner, axis, "xyz", 3, required=False)
                if xyz is not None and not any(xyz):
                    problems.fail(axis, f"{owner}: <axis xyz> is zero")
        if kind in ("revolute", "prismatic"):
            limit = joint.find("limit")
            if limit is None:
                problems.fail(joint, f"{owner} ({kind}) has no <limit lower=... upper=...>")
            else:
                lower = problems.numbers(owner, limit, "lower", 1)
                upper = problems.numbers(owner, limit, "upper", 1)
                if lower is not None and upper is not None and lower[0] > upper[0]:
                    problems.fail(limit, f"{owner}: lower limit {lower[0]} is above upper limit {upper[0]}")
    for joint in joints.values():
        mimic = joint.find("mimic")
        if mimic is not None:
            followed = mimic.attributes.get("joint")
            if followed not in joints:
                problems.fail(mimic, f"{joint.describe()} mimics joint {followed!r}, not a <joint> of the file")
            problems.numbers(f"joint {joint.attributes['name']!r}", mimic, "multiplier", 1, required=False)
            problems.numbers(f"joint {joint.attributes['name']!r}", mimic, "offset", 1, required=False)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        problems.fail(
            robot, f"the links must form one tree with one root link; links without a parent joint: {roots or 'none'}"
        )
    for name in links:  # every link reaches the root: no cycles
        seen, current = set(), name
        while current in parent_of:
            if current in seen:
                problems.fail(joints[parent_of[current]], f"the joints form a cycle through link {current!r}")
            seen.add(current)
            current = next(c.attributes["link"] for c in joints[parent_of[current]].children if c.tag == "parent")


def _check_collision(problems: _Problems, link: _Node, collision: _Node) -> None:
    owner = f"link {link.attributes['name']!r}"
    origin = collision.find("origin")
    if origin is not None:
        problems.numbers(owner, origin, "xyz", 3, required=False)
        problems.numbers(owner, origin, "rpy", 3, required=False)
    geometry = collision.find("geometry")
    shapes = (
        [] if geometry is None else [c for c in geometry.children if c.tag in ("box", "sphere", "cylinder", "mesh")]
    )
    if geometry is None or len(shapes) != 1:
        problems.fail(
            collision if geometry is None else geometry,
            f"{owner}: <collision> needs a <geometry> with one of <box>, <sphere>, <cylinder>, <mesh>",
        )
    shape = shapes[0]
    sizes = {"box": [("size", 3)], "sphere": [("radius", 1)], "cylinder": [("radius", 1), ("length", 1)], "mesh": []}
    for attribute, count in sizes[shape.tag]:
        values = problems.numbers(owner, shape, attribute, count)
        if values is not None and not all(v > 0 for v in values):
            problems.fail(shape, f"{owner}: <{shape.tag} {attribute}> must be positive, got {values}")
    if shape.tag == "mesh":
        if not shape.attributes.get("filename"):
            problems.fail(shape, f"{owner}: <mesh> has no 'filename' attribute")
        problems.numbers(owner, shape, "scale", 3, required=False)
