"""A URDF robot among obstacles: kinematics, collision geometry, screening, the exact checker,
and the bounds behind certified motions. Knows nothing of planners; the OMPL adapters are in
:mod:`ompl_balance.validity`."""
