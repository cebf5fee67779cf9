"""Run records and the results file ``results.jsonl`` that holds them.

A record is one finished run as JSON: ``problem``, ``planner`` (label), ``run`` (index),
``seed``, ``definition`` (digest of its cell's definition), ``status`` (OMPL's status
name), ``properties`` (OMPL log names and types: ``"time REAL"``, ...), ``params`` (the
planner's parameters as OMPL strings), ``error`` (empty unless the run crashed, was killed
or raised), ``improves_cost`` (the planner keeps improving its solution until its time
limit, as RRT* does), and optionally ``progress`` (sampled progress properties), ``note``
and ``param_names``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ompl import base as ob

from .experiment import RunTask

Record = dict[str, Any]

#: OMPL's planner status names -> the index the OMPL log's ``status`` enum uses.
STATUS_INDEX = {
    name: member.value
    for name, member in ob.PlannerStatus.PlannerStatusType.__members__.items()
    if name != "TYPE_COUNT"
}


def status_name(status: ob.PlannerStatus) -> str:
    """The ``PlannerStatusType`` member name of a ``PlannerStatus`` (``"EXACT_SOLUTION"``, ...)."""
    for name, member in ob.PlannerStatus.PlannerStatusType.__members__.items():
        if status == member:
            return name
    return "UNKNOWN"


def failure_properties(status: str, elapsed: float) -> dict[str, Any]:
    """The run properties of a run that failed: its time, OMPL's status index and not solved."""
    return {"time REAL": elapsed, "status ENUM": STATUS_INDEX[status], "solved BOOLEAN": 0}


def run_record(
    task: RunTask,
    status: str,
    properties: dict[str, Any],
    params: dict[str, str] | None = None,
    error: str = "",
    improves_cost: bool = False,
) -> Record:
    """The record of ``task`` with these results."""
    return {
        "problem": task.problem.name,
        "planner": task.planner.label,
        "run": task.run,
        "seed": task.seed,
        "definition": task.definition,
        "status": status,
        "properties": properties,
        "params": params or {},
        "error": error,
        "improves_cost": improves_cost,
    }


def failure_record(task: RunTask, status: str, elapsed: float, error: str) -> Record:
    """The record of a run whose process died or had to be killed (OMPL's ``CRASH`` status)."""
    return run_record(task, status, failure_properties(status, elapsed), error=error)


class ResultStore:
    """``results.jsonl``: one JSON record per finished run, appended and flushed at once.

    A line cut short by a killed process is ignored when reading (and the next record
    starts on a fresh line).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path).absolute()

    def records(self) -> list[Record]:
        if not self.path.exists():
            return []
        records = []
        for line in self.path.read_text().splitlines():
            try:
                records.append(json.loads(line))
            except json.JSONDecodeError:
                continue  # the tail of an interrupted write
        return records

    def finished(self) -> set[tuple[tuple[str, str, int], str]]:
        """``(key, definition)`` of every recorded run."""
        return {((r["problem"], r["planner"], r["run"]), r.get("definition", "")) for r in self.records()}

    def append(self, record: Record) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("a+") as file:
            file.seek(0, os.SEEK_END)
            if file.tell() > 0:
                file.seek(file.tell() - 1)
                if file.read(1) != "\n":
                    file.write("\n")
            file.write(json.dumps(record) + "\n")
            file.flush()
            os.fsync(file.fileno())

    def rewrite(self, records: list[Record]) -> None:
        """Replace the file by ``records``, atomically (a crash leaves the old file or the new one)."""
        temporary = self.path.with_suffix(".jsonl.tmp")
        with temporary.open("w") as file:
            file.writelines(json.dumps(record) + "\n" for record in records)
            file.flush()
            os.fsync(file.fileno())
        os.replace(temporary, self.path)
