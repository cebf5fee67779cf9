"""Problems to plan in: the built-in 2-D box worlds, occupancy grids, the shipped
MotionBenchMaker Panda scenarios and OMPL's own 2-D test environments."""
