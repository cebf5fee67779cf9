"""Rigid bodies: a mesh robot (or several shapes rigidly joined) moving in SE(2) or SE(3) among
static obstacles, as OMPL.app's problems describe them.

* :mod:`~ompl_balance.collision.rigid.body`: :class:`RigidBody`, its parts and state layouts;
* :mod:`~ompl_balance.collision.rigid.pieces`: cutting a triangle soup into compact pieces;
* :mod:`~ompl_balance.collision.rigid.motion`: poses of states and OMPL's interpolation, compiled;
* :mod:`~ompl_balance.collision.rigid.view`: the compiled view (:class:`RigidView`) and the
  state kernel;
* :mod:`~ompl_balance.collision.rigid.advance`: the certified-edge kernel (conservative
  advancement along OMPL's interpolation);
* :mod:`~ompl_balance.collision.rigid.checker`: :class:`RigidBodyChecker`, the Python API
  and the FCL queries the kernels leave undecided.
"""
