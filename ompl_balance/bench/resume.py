"""The output folder: whose it is, which finished runs in it still count, and what went stale.

An output folder belongs to one experiment (by name, in ``experiment.json``): running another
experiment into it is refused, as is a folder that is not empty and not an output folder.
A finished run counts for the experiment when it is one of its runs (same problem, planner
label and run index) and was recorded under the same definition of its cell
(:meth:`~ompl_balance.bench.experiment.Experiment.cell_definition`: problem and planner
specs, seed, limits, versions of this package and OMPL). When the experiment is run into its
folder after its definition changed, :func:`claim` moves the records of the changed cells to
``superseded/results.jsonl`` (nothing is deleted) so those cells run again, keeps every other
record, and says what changed. Files made from the records (logs, plots) that the current
definition no longer makes, such as the log of a problem dropped from the experiment, go to
``superseded/`` too (:func:`supersede_files`), so the folder holds only what its current
definition produced.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import ExperimentError
from .experiment import RUN_DEFINING_FIELDS, Experiment, versions
from .results import Record, ResultStore

EXPERIMENT_FILE = "experiment.json"
RESULTS_FILE = "results.jsonl"
#: What earlier definitions produced: ``results.jsonl`` (their runs), ``logs/``, ``plots/``.
SUPERSEDED = "superseded"
_OLD_SUPERSEDED_FILE = "superseded.jsonl"  # where ompl-balance 0.2.0 kept superseded runs


@dataclass
class Claim:
    """What :func:`claim` found in the folder."""

    kept: int = 0  # finished runs of this experiment, reused
    superseded: int = 0  # runs recorded under another definition, moved to superseded/results.jsonl
    cells: list[tuple[str, str]] = field(default_factory=list)  # (problem, planner) cells they belong to
    changes: list[str] = field(default_factory=list)  # what differs from the folder's experiment.json

    def message(self, out: Path) -> str:
        """The notice for the user; empty when nothing was superseded."""
        if not self.superseded:
            return ""
        what = "; ".join(self.changes) or "runs recorded under another definition (experiment.json gives no details)"
        runs, cells = _count(self.superseded, "run"), _count(len(self.cells), "cell")
        return (
            f"{out} holds runs of another definition ({what}): {runs} of {cells} moved to "
            f"{SUPERSEDED}/{RESULTS_FILE} and run again; {_count(self.kept, 'finished run')} kept"
        )


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}{'s' * (number != 1)}"


def experiment_file_content(experiment: Experiment) -> dict[str, Any]:
    """What ``experiment.json`` holds: the experiment and the versions its runs execute with."""
    return {**experiment.as_dict(), "versions": versions()}


def _as_json(value: Any) -> Any:
    return json.loads(json.dumps(value, default=str))


def describe_changes(previous: Mapping[str, Any], current: Mapping[str, Any]) -> list[str]:
    """The differences that change run results between two ``experiment.json`` contents, in words
    (``"planner 'RRTConnect': params {'range': '0.1'} -> {'range': '0.3'}"``). Problems and
    planners only in one of them are not changes of a definition."""
    previous, current = _as_json(previous), _as_json(current)
    changes = [
        f"{key} {previous.get(key)!r} -> {current[key]!r}"
        for key in RUN_DEFINING_FIELDS
        if previous.get(key) != current[key]
    ]
    changes += [
        f"{package} {previous.get('versions', {}).get(package, 'unknown')} -> {version}"
        for package, version in current["versions"].items()
        if previous.get("versions", {}).get(package) != version
    ]
    for kind, key in (("problem", "name"), ("planner", "label")):
        before = {item[key]: item for item in previous.get(f"{kind}s", [])}
        for item in current[f"{kind}s"]:
            old = before.get(item[key])
            differing = [
                f"{name} {old.get(name)!r} -> {value!r}"
                for name, value in item.items()
                if old and (name in old or value) and old.get(name) != value  # a new empty field is no change
            ]
            if differing:
                changes.append(f"{kind} {item[key]!r}: {', '.join(differing)}")
    return changes


def _previous_experiment(out: Path, experiment: Experiment) -> dict[str, Any] | None:
    """The folder's ``experiment.json`` (``None`` for a new or empty folder); :class:`ExperimentError`
    for a folder that cannot be made, is a file, belongs to another experiment or is not an output folder."""
    if out.exists() and not out.is_dir():
        raise ExperimentError(
            str(out), "is a file; the output folder (-o) must be a new or empty folder, or one this experiment ran into"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise ExperimentError(str(out), f"cannot make the output folder: {error.strerror or error}") from error
    path = out / EXPERIMENT_FILE
    if not path.is_file():
        if any(out.iterdir()):
            raise ExperimentError(
                str(out),
                f"is not empty and holds no {EXPERIMENT_FILE}, so it is not an output folder of ompl-balance: "
                "give a new or empty folder",
            )
        return None
    try:
        previous: dict[str, Any] = json.loads(path.read_text())
        name = previous["name"]
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ExperimentError(str(path), f"cannot be read as an output folder's experiment ({error})") from error
    if name != experiment.name:
        raise ExperimentError(
            str(out),
            f"holds the results of experiment {name!r} ({EXPERIMENT_FILE}), not of {experiment.name!r}: "
            "give another folder",
        )
    return previous


def claim(out: Path, experiment: Experiment) -> Claim:
    """Make ``out`` the folder of ``experiment``: supersede runs recorded under another definition
    of one of its cells, keep all others, and write ``experiment.json``.

    :class:`ExperimentError` (nothing changed) when ``out`` is a file, cannot be made, holds
    another experiment or is a folder of something else."""
    previous = _previous_experiment(out, experiment)
    store = ResultStore(out / RESULTS_FILE)
    superseded = ResultStore(out / SUPERSEDED / RESULTS_FILE)
    old_layout = out / _OLD_SUPERSEDED_FILE
    if old_layout.is_file():
        for record in ResultStore(old_layout).records():
            superseded.append(record)
        old_layout.unlink()
    definitions = {task.key: task.definition for task in experiment.tasks()}
    records = store.records()
    stale = [r for r in records if _key(r) in definitions and not _counts(r, definitions)]
    result = Claim(kept=sum(_counts(r, definitions) for r in records))
    if stale:
        current = experiment_file_content(experiment)
        result.changes = describe_changes(previous, current) if previous is not None else []
        result.superseded = len(stale)
        result.cells = sorted({(r["problem"], r["planner"]) for r in stale})
        for record in stale:
            superseded.append(record)
        stale_ids = {id(record) for record in stale}
        store.rewrite([r for r in records if id(r) not in stale_ids])
    (out / EXPERIMENT_FILE).write_text(json.dumps(experiment_file_content(experiment), indent=1))
    return result


def supersede_files(out: Path, folder: str, current: Iterable[Path]) -> list[Path]:
    """Move the files in ``out/folder`` other than ``current`` to ``out/superseded/folder`` (an
    earlier superseded copy of the same name is replaced); returns where they went."""
    kept = {path.resolve() for path in current}
    moved = []
    source = out / folder
    for path in sorted(source.glob("*")) if source.is_dir() else []:
        if path.is_file() and path.resolve() not in kept:
            target = out / SUPERSEDED / folder / path.name
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(path, target)
            moved.append(target)
    return moved


def _key(record: Record) -> tuple[str, str, int]:
    return (record["problem"], record["planner"], record["run"])


def _counts(record: Record, definitions: Mapping[tuple[str, str, int], str]) -> bool:
    """Whether ``record`` is one of the runs ``definitions`` lists, recorded under its definition."""
    return _key(record) in definitions and record.get("definition") == definitions[_key(record)]


def experiment_records(experiment: Experiment, store: ResultStore) -> list[Record]:
    """The records in ``store`` that count for ``experiment``: its runs, recorded under its definitions."""
    definitions = {task.key: task.definition for task in experiment.tasks()}
    return [r for r in store.records() if _counts(r, definitions)]
