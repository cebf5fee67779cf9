"""Looking at plans: a problem and its plan in the browser, live or as one offline HTML file.

:func:`show` takes an ``og.SimpleSetup`` after a solve (or a checker and a path, or one of the
package's problems) and shows the robot or body (its collision geometry; a URDF's visual meshes
where it has them), the obstacles, the start and goal, the path animated (a slider and a play
button) and, on request, the planner's trees (the end effector's or body's position at each
node). ``ompl-balance show PROBLEM`` plans a problem by name and shows it the same way.

The viewer is viser's (the ``viz`` extra, imported only when something is shown): a server on
this machine for the live view, and viser's self-contained HTML export for the file, which a
browser opens from disk with no network and no Python. The modules, one concept each:

``scene``
    what is drawn, independent of the viewer: meshes, moving frames, what a state does to them;
``problems``
    the scenes of a ``SimpleSetup``, of the package's problems, and of the problems ``show`` names;
``plan``
    the path, trees, start and goal read from a solve; the animation's frames;
``camera``, ``style``
    where the view starts; the colours of the layers;
``render``
    the scene and plan drawn with viser;
``page``, ``live``
    the HTML file; the live viewer;
``api``, ``command``
    :func:`show`; the ``show`` command (plan a named problem, then show it);
``extra``
    viser, and the message naming the extra when it is missing.
"""

from __future__ import annotations

from .api import show

__all__ = ["show"]
