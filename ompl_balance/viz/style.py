"""The viewer's colours (RGB, 0-255) and opacities: one hue per layer, so a picture reads at a glance
(and a test can find the robot by its colour)."""

from __future__ import annotations

Colour = tuple[int, int, int]

#: The robot or body (its collision geometry): orange.
ROBOT: Colour = (245, 130, 20)
#: Visual meshes that have no colour of their own: light grey.
VISUAL: Colour = (200, 200, 205)
#: Obstacles: slate grey, see-through in 3-D worlds so that a robot inside a cage stays visible.
OBSTACLE: Colour = (120, 135, 160)
OBSTACLE_OPACITY = 0.3
#: Obstacles of a 2-D world (drawn as low blocks seen from above): opaque, darker.
BLOCK: Colour = (95, 105, 125)
#: The robot at the start and at the goal: translucent green and purple.
START: Colour = (40, 170, 80)
GOAL: Colour = (150, 80, 200)
GHOST_OPACITY = 0.3
#: The traced point's path (end effector, body origin).
PATH: Colour = (20, 120, 60)
#: Trees by name: the start tree blue, the goal tree purple, a single tree blue.
TREES: dict[str, Colour] = {"start tree": (40, 110, 220), "goal tree": (190, 60, 190), "tree": (40, 110, 220)}
#: What collides: red.
CONTACT: Colour = (220, 30, 30)
