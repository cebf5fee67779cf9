"""The viewer in a real browser (headless Chromium, software WebGL): the written file and the live
viewer draw the robot where it stands.

The oracle is a projection worked out here (``picture_oracles``): the robot's collision meshes at
a frame's state, through the camera the page opens with, give the pixels the robot must cover.
The picture must have the robot's orange there and (nearly) nowhere else, two frames of the path
must differ as their projections do, and the obstacles must show where they project. Without
Chromium these tests skip, saying so.
"""

import math
import socket
import urllib.request

import numpy as np
import pytest
from browser import Browser, Playback, chromium_or_skip
from picture_oracles import grown, orange, overlap, red, robot_meshes, silhouette

from ompl_balance.viz.api import scene_and_plan
from ompl_balance.viz.command import plan_named
from ompl_balance.viz.live import LiveViewer
from ompl_balance.viz.page import write_page
from ompl_balance.viz.plan import animation_frames
from ompl_balance.worlds.rigid import rigid_problem

WIDTH, HEIGHT = 1000, 700


def _frame_at(page, seconds):
    """The animation frame a written file shows at ``seconds`` of its timeline."""
    return min(math.floor(seconds / page.frame_seconds + 1e-6), len(page.frames) - 1)


def _assert_robot_drawn(picture, scene, state, camera, canvas, exclude=None):
    """The robot's orange covers the projection of the robot at ``state`` and lies almost only
    there; returns the orange mask."""
    size = (picture.shape[1], picture.shape[0])
    expected = silhouette(robot_meshes(scene, state), camera, canvas, size)
    drawn = orange(picture)
    if exclude is not None:
        drawn &= ~exclude
        expected &= ~exclude
    assert expected.sum() > 500, "the robot should project onto a good part of the picture"
    assert drawn.sum() > 0.4 * expected.sum(), f"robot orange: {drawn.sum()} px where {expected.sum()} expected"
    inside = (drawn & grown(expected)).sum() / drawn.sum()
    assert inside > 0.95, f"only {inside:.0%} of the orange is where the robot stands"
    covered = (drawn & expected).sum() / expected.sum()
    assert covered > 0.5, f"the robot's orange covers only {covered:.0%} of where it stands"
    return drawn, expected


def _assert_obstacles_drawn(picture, scene, camera, canvas, robot):
    """Where obstacles project (the robot's pixels aside), the picture is not the white background."""
    size = (picture.shape[1], picture.shape[0])
    meshes = [(mesh.mesh, mesh.pose) for mesh in scene.obstacles]
    where = silhouette(meshes, camera, canvas, size) & ~grown(robot, 2)
    assert where.sum() > 2000
    shaded = (picture[where].astype(int).min(axis=1) < 240).mean()
    assert shaded > 0.9, f"only {shaded:.0%} of where the obstacles project is drawn"


def _planned_panda():
    """table_pick.001 planned as ``ompl-balance show`` plans it: its scene, plan and frames."""
    planned = plan_named("table_pick.001")
    assert planned.solved
    return planned.problem.scene, planned.plan, planned.frames


def _cage_path():
    """se3_cage with a path out of the cage's window given as states (what is drawn, not how it was found)."""
    problem = rigid_problem("se3_cage")
    upright = problem.start[3:]
    through = [np.array([0.4, 0.0, 0.0, *upright]), np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])]
    scene, plan = scene_and_plan(problem, np.stack([problem.start, *through, problem.goal]), False)
    return scene, plan, animation_frames(scene, plan.path, 150)


@pytest.mark.parametrize("make", [_planned_panda, _cage_path], ids=["panda table_pick.001", "rigid body se3_cage"])
def test_the_written_file_draws_the_robot_where_each_frame_puts_it(make, tmp_path):
    executable = chromium_or_skip()
    scene, plan, frames = make()
    page = write_page(scene, plan, frames, tmp_path / "plan.html")
    assert page.path.stat().st_size < 20e6
    with Browser(WIDTH, HEIGHT, executable) as browser:
        browser.open(page.path.as_uri())  # from disk: nothing but the file
        playback = Playback(browser)
        playback.wait_loaded()
        pictures = []
        for fraction in (0.2, 0.75):  # forward only: seeking back replays the scene from its start
            playback.seek(fraction)
            picture = browser.settled()
            k = _frame_at(page, playback.time())
            drawn, expected = _assert_robot_drawn(picture, scene, page.frames[k], page.camera, playback.canvas())
            pictures.append((k, drawn, expected))
        _assert_obstacles_drawn(picture, scene, page.camera, playback.canvas(), drawn)
    (k1, drawn1, expected1), (k2, drawn2, expected2) = pictures
    assert k2 > k1
    assert overlap(drawn1, drawn2) < 0.8, "two frames of the path look alike"
    # each picture is of its own frame: it matches its projection better than the other's
    assert overlap(drawn1, expected1) > overlap(drawn1, expected2)
    assert overlap(drawn2, expected2) > overlap(drawn2, expected1)


def test_the_live_viewer_moves_the_robot_to_the_frame_asked_for():
    executable = chromium_or_skip()
    scene, plan, frames = _planned_panda()
    viewer = LiveViewer(scene, plan, frames, host="127.0.0.1", port=0)
    try:
        with Browser(WIDTH, HEIGHT, executable) as browser:
            browser.open(viewer.url)
            browser.wait_for("document.querySelector('canvas') !== null")
            browser.dismiss_notifications()
            masks = []
            for k in (len(frames) // 5, 4 * len(frames) // 5):
                viewer.frame = k
                picture = browser.settled()
                canvas = browser.rectangle("canvas")
                drawn, expected = _assert_robot_drawn(picture, scene, frames[k], viewer.drawing.camera, canvas)
                masks.append((drawn, expected))
        (drawn1, expected1), (drawn2, expected2) = masks
        assert overlap(drawn1, drawn2) < 0.8
        assert overlap(drawn1, expected1) > overlap(drawn1, expected2)
    finally:
        viewer.stop()


@pytest.mark.slow
def test_an_invalid_start_is_painted_red_where_it_collides(tmp_path):
    """A Panda start in collision: no path; the links in contact, and what they touch, red."""
    executable = chromium_or_skip()
    from ompl import geometric as og

    from ompl_balance import BalancedRRTConnect

    planned = plan_named("table_pick.001")
    start = np.array([0.52, 1.43, 0.23, -0.98, 1.84, 2.68, 1.93])  # the forearm into the table top
    si = planned.problem.setup().getSpaceInformation()
    ss = og.SimpleSetup(si)
    a, b = si.allocState(), si.allocState()
    for i, (x, y) in enumerate(zip(start, planned.problem.goal)):
        a[i], b[i] = float(x), float(y)
    ss.setStartAndGoalStates(a, b)
    ss.setPlanner(BalancedRRTConnect(si))
    ss.solve(1.0)
    assert not ss.haveSolutionPath()
    scene, plan = scene_and_plan(ss, None, False)
    assert np.allclose(plan.start, start) and len(plan.path) == 0
    contacts = scene.collisions(start)
    assert [str(c) for c in contacts] == ["panda_link5 with obstacle 'table_top'"]
    assert scene.problem(start) == "in collision: panda_link5 with obstacle 'table_top'"
    page = write_page(scene, plan, plan.start[None], tmp_path / "stuck.html")
    with Browser(WIDTH, HEIGHT, executable) as browser:
        browser.open(page.path.as_uri())
        browser.wait_for("document.querySelector('canvas') !== null")
        browser.dismiss_notifications()
        picture = browser.settled()
        canvas = browser.rectangle("canvas")
    size = (picture.shape[1], picture.shape[0])
    poses = scene.frame_poses(start[None])[0]
    links = {c.first_index for c in contacts} | {c.second_index for c in contacts if c.kind == "self"}
    hit = [(part.mesh, poses[f] @ part.pose) for k, (f, part) in enumerate(scene.parts) if k in links]
    obstacles = [scene.obstacles[c.second_index] for c in contacts if c.kind == "obstacle"]
    touched = [(obstacle.mesh, obstacle.pose) for obstacle in obstacles]
    where_links = silhouette(hit, page.camera, canvas, size)
    where = where_links | silhouette(touched, page.camera, canvas, size)
    painted = red(picture)
    assert painted.sum() > 200
    assert (painted & grown(where)).sum() / painted.sum() > 0.9, "red away from what collides"
    assert (painted & where_links).sum() > 0.3 * where_links.sum(), "the colliding links are not red"


def _own_addresses():
    """This machine's IPv4 addresses but loopback (Linux: each interface's, by ioctl)."""
    import fcntl
    import struct

    found = set()
    for _index, name in socket.if_nameindex():
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            try:
                packed = fcntl.ioctl(probe.fileno(), 0x8915, struct.pack("256s", name[:15].encode()))  # SIOCGIFADDR
            except OSError:
                continue
        found.add(socket.inet_ntoa(packed[20:24]))
    return found - {"127.0.0.1"}


def _listening_on(port):
    """The local addresses (hex, as /proc/net/tcp writes them) of sockets listening on ``port``."""
    with open("/proc/net/tcp") as table:
        rows = [line.split() for line in table.read().splitlines()[1:]]
    return {row[1].split(":")[0] for row in rows if row[3] == "0A" and int(row[1].split(":")[1], 16) == port}


def test_the_live_viewer_listens_on_this_machine_only():
    planned = plan_named("open")
    viewer = LiveViewer(planned.problem.scene, planned.plan, planned.frames, port=0)
    try:
        with urllib.request.urlopen(viewer.url, timeout=10) as answer:
            assert answer.status == 200 and b"<html" in answer.read(2000).lower()
        assert viewer.url == f"http://127.0.0.1:{viewer.port}"
        assert _listening_on(viewer.port) == {"0100007F"}  # 127.0.0.1, and nothing else
        for address in _own_addresses():
            with pytest.raises(OSError):
                socket.create_connection((address, viewer.port), timeout=2).close()
    finally:
        viewer.stop()
