"""Resuming a sweep in an output folder: which finished runs still count, and what changed.

A finished run counts for an experiment when it is one of the experiment's runs (same
problem, planner label and run index) and was recorded under the same definition of its
cell (:meth:`~ompl_balance.bench.experiment.Experiment.cell_definition`: problem and
planner specs, seed, limits, versions of this package and OMPL). When an experiment is
run into a folder holding runs recorded under another definition, :func:`claim` moves
those records to ``superseded.jsonl`` (nothing is deleted) so their cells run again, keeps
every other record, and says what changed.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .experiment import RUN_DEFINING_FIELDS, Experiment, versions
from .runner import Record, ResultStore

EXPERIMENT_FILE = "experiment.json"
RESULTS_FILE = "results.jsonl"
SUPERSEDED_FILE = "superseded.jsonl"


@dataclass
class Claim:
    """What :func:`claim` found in the folder."""

    kept: int = 0  # finished runs of this experiment, reused
    superseded: int = 0  # runs recorded under another definition, moved to superseded.jsonl
    cells: list[tuple[str, str]] = field(default_factory=list)  # (problem, planner) cells they belong to
    changes: list[str] = field(default_factory=list)  # what differs from the folder's experiment.json

    def message(self, out: Path) -> str:
        """The notice for the user; empty when nothing was superseded."""
        if not self.superseded:
            return ""
        what = "; ".join(self.changes) or "runs recorded under another definition (experiment.json gives no details)"
        runs, cells = _count(self.superseded, "run"), _count(len(self.cells), "cell")
        return (
            f"{out} holds runs of another definition ({what}): {runs} of {cells} moved to {SUPERSEDED_FILE} "
            f"and run again; {_count(self.kept, 'finished run')} kept"
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


def claim(out: Path, experiment: Experiment) -> Claim:
    """Make ``out`` the folder of ``experiment``: supersede runs recorded under another definition
    of one of its cells, keep all others, and write ``experiment.json``."""
    out.mkdir(parents=True, exist_ok=True)
    store = ResultStore(out / RESULTS_FILE)
    definitions = {task.key: task.definition for task in experiment.tasks()}
    records = store.records()
    stale = [r for r in records if _key(r) in definitions and not _counts(r, definitions)]
    result = Claim(kept=sum(_counts(r, definitions) for r in records))
    if stale:
        current = experiment_file_content(experiment)
        path = out / EXPERIMENT_FILE
        result.changes = describe_changes(json.loads(path.read_text()), current) if path.exists() else []
        result.superseded = len(stale)
        result.cells = sorted({(r["problem"], r["planner"]) for r in stale})
        superseded = ResultStore(out / SUPERSEDED_FILE)
        for record in stale:
            superseded.append(record)
        stale_ids = {id(record) for record in stale}
        _rewrite(store.path, [r for r in records if id(r) not in stale_ids])
    (out / EXPERIMENT_FILE).write_text(json.dumps(experiment_file_content(experiment), indent=1))
    return result


def _key(record: Record) -> tuple[str, str, int]:
    return (record["problem"], record["planner"], record["run"])


def _counts(record: Record, definitions: Mapping[tuple[str, str, int], str]) -> bool:
    """Whether ``record`` is one of the runs ``definitions`` lists, recorded under its definition."""
    return _key(record) in definitions and record.get("definition") == definitions[_key(record)]


def _rewrite(path: Path, records: list[Record]) -> None:
    """Replace ``path`` by ``records``, atomically (a crash leaves the old file or the new one)."""
    temporary = path.with_suffix(".jsonl.tmp")
    with temporary.open("w") as file:
        file.writelines(json.dumps(record) + "\n" for record in records)
        file.flush()
        os.fsync(file.fileno())
    os.replace(temporary, path)


def experiment_records(experiment: Experiment, store: ResultStore) -> list[Record]:
    """The records in ``store`` that count for ``experiment``: its runs, recorded under its definitions."""
    definitions = {task.key: task.definition for task in experiment.tasks()}
    return [r for r in store.records() if _counts(r, definitions)]
