"""Why RRT*'s ball-radius constant matters: six figures, written as PNG files.

1. ``radius_vs_n_by_dimension.png``: the unsaturated radius ``(gamma log N / N)^(1/d)``
   for d = 2, 3, 6, 10 (gamma = 1).
2. ``radius_vs_n_by_gamma.png``: the radius for several gamma at d = 3 (eta = 0.1 in a
   unit cube).
3. ``neighbours_vs_n.png``: the expected number of tree nodes in the ball,
   ``N * zeta_d r^d / mu_free``, for those gammas: equal while the radius is saturated at
   eta, then each grows like ``zeta_d gamma log N / mu_free``.
4. ``tree_gamma_100_vs_estimated.png``: BallRadiusRRTstar's tree and path on the rooms
   map with gamma = 100 (MATLAB's default) and with the estimated gamma, same seed and
   iterations.
5. ``cost_vs_iterations.png``: best path cost against iterations for a range of gamma
   (median and interquartile band over the seeds).
6. ``time_vs_gamma.png``: median planning time for those runs, per gamma.

Run: python examples/ball_radius_constant.py OUTPUT_DIR [--seeds 10] [--iterations 2000]
(the defaults, 3 seeds and 600 iterations, take well under a minute).
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

try:
    import matplotlib
except ImportError:  # the plot extra
    raise SystemExit("ball_radius_constant.py draws with matplotlib: pip install 'ompl-balance[plot]'") from None

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from ompl import util as ou

from ompl_balance.gamma import ball_radius_constant, estimate_ball_radius_constant, rewire_radius, unit_ball_volume
from ompl_balance.rrtstar import BallRadiusRRTstar
from ompl_balance.worlds.occupancy import OccupancyProblem, rooms_problem

ETA = 4.0  # m, maximum connection distance on the rooms map


def plot_radius_by_dimension(out: Path) -> None:
    counts = np.logspace(0.5, 7, 300)
    fig, ax = plt.subplots(figsize=(6, 4))
    for d in (2, 3, 6, 10):
        ax.plot(counts, rewire_radius(counts, d, 1.0), label=f"d = {d}")
    ax.set(xscale="log", xlabel="tree nodes N", ylabel="radius (gamma = 1)", title="Unsaturated RRT* radius")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "radius_vs_n_by_dimension.png", dpi=120)
    plt.close(fig)


GAMMAS_D3 = (1.0, 10.0, 100.0, 1000.0)


def plot_radius_and_neighbours_by_gamma(out: Path, eta: float = 0.1, free_measure: float = 1.0) -> None:
    d = 3
    counts = np.logspace(0.5, 9, 400)
    radius_fig, radius_ax = plt.subplots(figsize=(6, 4))
    count_fig, count_ax = plt.subplots(figsize=(6, 4))
    for gamma in GAMMAS_D3:
        radii = rewire_radius(counts, d, gamma, eta)
        radius_ax.plot(counts, radii, label=f"gamma = {gamma:g}")
        count_ax.plot(counts, counts * unit_ball_volume(d) * radii**d / free_measure, label=f"gamma = {gamma:g}")
    radius_ax.set(
        xscale="log", yscale="log", xlabel="tree nodes N", ylabel="radius", title=f"RRT* radius, d = 3, eta = {eta}"
    )
    radius_ax.legend()
    count_ax.set(
        xscale="log",
        yscale="log",
        xlabel="tree nodes N",
        ylabel="expected nodes in the ball",
        title="Neighbours: ~N while saturated, then ~gamma log N",
    )
    count_ax.legend()
    for fig, name in ((radius_fig, "radius_vs_n_by_gamma.png"), (count_fig, "neighbours_vs_n.png")):
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)


def plan(problem: OccupancyProblem, gamma: float, seed: int, iterations: int) -> tuple[BallRadiusRRTstar, np.ndarray]:
    """One seeded BallRadiusRRTstar run on ``problem``: the planner (tree, stats) and the path, ``(n, 2)`` m."""
    ss = problem.setup()
    planner = BallRadiusRRTstar(ss.getSpaceInformation())
    planner.setBallRadiusConstant(gamma)
    planner.setRange(ETA)
    planner.setMaxIterations(iterations)
    planner.setSeed(seed)
    ss.setPlanner(planner)
    ss.solve(600.0)
    path = ss.getSolutionPath()
    points = [path.getState(i)[0:2] for i in range(path.getStateCount())] if ss.haveExactSolutionPath() else []
    return planner, np.array(points).reshape(-1, 2)


def draw_tree(ax, problem: OccupancyProblem, planner: BallRadiusRRTstar, path: np.ndarray, title: str) -> None:
    grid = problem.grid
    ax.imshow(
        grid.occupied, origin="lower", extent=(grid.low[0], grid.high[0], grid.low[1], grid.high[1]), cmap="Greys"
    )
    data = planner.plannerData()
    points = np.array([data.getVertex(i).getState()[0:2] for i in range(data.numVertices())])
    segments = [(points[a], points[b]) for a in range(data.numVertices()) for b in data.getEdges(a)]
    ax.add_collection(LineCollection(segments, colors="tab:blue", linewidths=0.4))
    ax.plot(path[:, 0], path[:, 1], color="tab:red", linewidth=2)
    ax.plot(*problem.start, "go"), ax.plot(*problem.goal, "r*", markersize=10)
    ax.set(title=f"{title}: cost {planner.stats.best_cost:.1f} m", xticks=[], yticks=[])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("output", type=Path, help="directory for the PNG files (created)")
    parser.add_argument("--seeds", type=int, default=3, help="seeds per gamma for figures 5 and 6 (default 3)")
    parser.add_argument("--iterations", type=int, default=600, help="iterations per run (default 600)")
    args = parser.parse_args()
    for option in ("seeds", "iterations"):
        if getattr(args, option) < 1:
            parser.error(f"--{option} must be a whole number >= 1, got {getattr(args, option)}")
    ou.setLogLevel(ou.LOG_WARN)
    args.output.mkdir(parents=True, exist_ok=True)

    plot_radius_by_dimension(args.output)
    plot_radius_and_neighbours_by_gamma(args.output)

    problem = rooms_problem()
    estimated = estimate_ball_radius_constant(problem.setup().getSpaceInformation(), rng=0)
    exact = ball_radius_constant(2, problem.grid.free_area)
    print(f"rooms map: estimated gamma {estimated:.0f} m^2 (exact gamma* {exact:.0f} m^2)")

    fig, axes = plt.subplots(1, 2, figsize=(11, 5.8), layout="constrained")
    for ax, gamma, title in (
        (axes[0], 100.0, "gamma = 100"),
        (axes[1], estimated, f"estimated gamma = {estimated:.0f}"),
    ):
        draw_tree(ax, problem, *plan(problem, gamma, seed=1, iterations=args.iterations), title)
    fig.savefig(args.output / "tree_gamma_100_vs_estimated.png", dpi=120)
    plt.close(fig)

    gammas = (10.0, 100.0, 1000.0, estimated, 10 * estimated)
    costs, times = {}, {}
    for gamma in gammas:
        runs = [plan(problem, gamma, seed, args.iterations)[0].stats for seed in range(1, args.seeds + 1)]
        costs[gamma] = np.array([run.best_costs for run in runs])
        times[gamma] = statistics.median(run.time for run in runs)
        print(
            f"gamma {gamma:8.0f}: median final cost {np.median(costs[gamma][:, -1]):.2f} m, median time {times[gamma]:.2f} s"
        )

    fig, ax = plt.subplots(figsize=(8.5, 4.5), layout="constrained")
    steps = np.arange(1, args.iterations + 1)
    # gammas whose runs are identical (their radius stays at eta over these iterations) share one curve
    same_runs: dict[bytes, list[float]] = {}
    for gamma in gammas:
        same_runs.setdefault(costs[gamma].tobytes(), []).append(gamma)
    for group, style in zip(same_runs.values(), ("-", "--", "-.", ":", (0, (5, 1)))):
        with np.errstate(invalid="ignore"):  # inf - inf between runs without a path yet: not drawn
            low, high = np.percentile(costs[group[0]], [25, 75], axis=0)
        mid = np.median(costs[group[0]], axis=0)  # as printed above; no line until half the runs have a path
        low, high, mid = (np.where(np.isfinite(values), values, np.nan) for values in (low, high, mid))
        names = ", ".join(f"{gamma:.0f}" for gamma in group)
        label = f"gamma = {names}" + (" (identical runs)" if len(group) > 1 else "")
        line = ax.plot(steps, mid, linestyle=style, label=label)[0]
        ax.fill_between(steps, low, high, color=line.get_color(), alpha=0.2)
    ax.set(
        xlabel="iterations",
        ylabel="best path cost (m)",
        title=f"Rooms map, {args.seeds} seeds: median and interquartile range",
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.savefig(args.output / "cost_vs_iterations.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.bar([f"{gamma:.0f}" for gamma in gammas], [times[gamma] for gamma in gammas])
    ax.set(
        xlabel="gamma (m^2)",
        ylabel=f"median time for {args.iterations} iterations (s)",
        title="Planning time against gamma",
    )
    fig.tight_layout()
    fig.savefig(args.output / "time_vs_gamma.png", dpi=120)
    plt.close(fig)
    print(f"figures written to {args.output}")


if __name__ == "__main__":
    main()
