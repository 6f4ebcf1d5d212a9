"""What the steps of one run did, gathered as they finish: each step's outcome, the plotted
ones, the findings and the time each part took (:class:`StepLog`)."""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.pipeline.steps import StepOutcome

__all__ = ["StepLog", "requested"]


@dataclass(slots=True)
class StepLog:
    """The steps of one run as they finish: every step's outcome by name (in the order the
    steps ran), those plotted, their findings in step order, and the seconds each part took."""

    outcomes: dict[str, StepOutcome] = field(default_factory=dict)
    plotted: dict[str, StepOutcome] = field(default_factory=dict)
    findings: list[dict[str, Any]] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)

    def skip(self, name: str, reason: str) -> None:
        """Record a step that did not run, and why."""
        self.outcomes[name] = StepOutcome("skipped", reason)

    def record(
        self, name: str, outcome: StepOutcome, plot: bool = True, findings: bool = True
    ) -> StepOutcome:
        """Record a step's outcome; ``plot`` puts it on the plotted axis, ``findings`` adds
        its findings."""
        self.outcomes[name] = outcome
        if plot:
            self.plotted[name] = outcome
        if findings:
            self.findings += outcome.findings
        return outcome

    @contextmanager
    def timed(self, key: str) -> Iterator[None]:
        """Time the block, in seconds, as ``timings[key]``."""
        clock = time.perf_counter()
        yield
        self.timings[key] = time.perf_counter() - clock


def requested(name: str, options: AnalysisOptions, steps: StepLog) -> bool:
    """Whether the options ask for step ``name``; a step not asked for is recorded as
    skipped ("not requested")."""
    if name in options.checks:
        return True
    steps.skip(name, "not requested")
    return False
