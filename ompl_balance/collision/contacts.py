"""What collides: the pairs of a checker's model in contact at one state, or the closest ones.

:meth:`CollisionChecker.collisions <ompl_balance.collision.checker.CollisionChecker.collisions>`
and :meth:`RigidBodyChecker.collisions <ompl_balance.collision.rigid.checker.RigidBodyChecker.collisions>`
answer with :class:`Contact` records; :func:`describe_contacts` puts them in words for messages
("panda_link7 with obstacle 'shelf', panda_hand with panda_link2 (self-collision)").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

#: ``Contact.kind`` of a pair of a robot geometry (or body part) and an obstacle.
OBSTACLE = "obstacle"
#: ``Contact.kind`` of a pair of two geometries of the same robot.
SELF = "self"


@dataclass(frozen=True)
class Contact:
    """One pair of a checker's model at one state: in contact, or ``distance`` metres apart.

    Attributes
    ----------
    first:
        The robot's geometry: its link's name (``"panda_link5"``; ``"panda_link5[1]"`` for the
        link's second ``<collision>`` element), or the rigid body part's name.
    second:
        The obstacle's name (``kind == "obstacle"``) or the other link geometry's name (``"self"``).
    kind:
        ``"obstacle"`` or ``"self"`` (self-collision of a robot).
    touching:
        Whether the two touch or overlap (FCL's collision test).
    distance:
        FCL's distance between the two (m); 0.0 for a pair in contact.
    first_index:
        Index of ``first`` in ``robot.geometries`` or ``body.parts``.
    second_index:
        Index of ``second`` in ``environment.obstacles`` (``"obstacle"``) or ``robot.geometries`` (``"self"``).
    """

    first: str
    second: str
    kind: str
    touching: bool
    distance: float
    first_index: int
    second_index: int

    def __str__(self) -> str:
        other = f"obstacle {self.second!r}" if self.kind == OBSTACLE else f"{self.second} (self-collision)"
        if self.touching:
            return f"{self.first} with {other}"
        return f"{self.first} {self.distance:.3g} m from {other}"


def describe_contacts(contacts: Sequence[Contact], limit: int = 6) -> str:
    """``contacts`` in words, at most ``limit`` of them and how many more ("" for none)."""
    words = ", ".join(str(contact) for contact in contacts[:limit])
    if len(contacts) > limit:
        words += f" and {len(contacts) - limit} more"
    return words


def geometry_names(links: Sequence[str]) -> list[str]:
    """Names of geometries owned by ``links`` (one entry per geometry): the link's name, with
    ``[k]`` appended for every geometry of a link that has more than one."""
    counts: dict[str, int] = {}
    for link in links:
        counts[link] = counts.get(link, 0) + 1
    seen: dict[str, int] = {}
    names = []
    for link in links:
        k = seen.get(link, 0)
        seen[link] = k + 1
        names.append(link if counts[link] == 1 else f"{link}[{k}]")
    return names
