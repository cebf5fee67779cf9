"""The compiled planning engine of the RRT-Connect family.

:class:`~ompl_balance.planners.BalancedRRTConnect` has two implementations of one loop: the
Python engine (any OMPL space; OMPL states or arrays; ``si.isValid``/``si.checkMotion``) and
the compiled engine of this package, for the spaces with a flat layout
(:mod:`ompl_balance.core.layout`):

* :mod:`~ompl_balance.engine.checks`: how the loop checks states and motions: a checker's
  compiled view (:mod:`ompl_balance.core.checks`), OMPL's discrete motion validator on top
  of a compiled state check, or calls to the space information's own checkers;
* :mod:`~ompl_balance.engine.loop`: the grow/connect loop, compiled, with the policies and
  the balancing rule;
* :mod:`~ompl_balance.engine.driver`: the Python side: inputs, goal feeding, growing the
  trees, polling the termination condition, the result;
* :mod:`~ompl_balance.engine.loading`: compiling or loading the engine in the background,
  so that no solve waits for numba.
"""
