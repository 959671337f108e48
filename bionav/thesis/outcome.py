"""What an item produces: value rows, checks, figures, and the verdict computed from them."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

HOLDS, PARTLY, FAILS, MISSING = "holds", "partly", "does not hold", "not produced"

#: the rule turning an item's checks into its verdict (stated in every report)
VERDICT_RULE = (
    "An item's verdict comes from its checks: every value row with a tolerance (|bionav - thesis| <= tolerance) "
    "and every stated claim check is one check. *holds*: all checks pass; *partly*: at least half pass; "
    "*does not hold*: fewer than half pass; *not produced*: none of the item's runs completed or no check could be "
    "evaluated (the section says why)."
)


def _num(x: Any) -> float | None:
    if isinstance(x, bool) or x is None:
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


@dataclass
class Row:
    """One quantity: the thesis' value, bionav's, and (for numbers) their difference."""

    quantity: str
    thesis: Any = None
    bionav: Any = None
    tolerance: float | None = None
    note: str = ""

    @property
    def difference(self) -> float | None:
        a, b = _num(self.thesis), _num(self.bionav)
        return None if a is None or b is None else b - a

    @property
    def passed(self) -> bool | None:
        """Within tolerance (None: no tolerance or a value is missing)."""
        d = self.difference
        if self.tolerance is None or d is None:
            return None
        return abs(d) <= self.tolerance + 1e-12

    @property
    def verdict(self) -> str:
        p = self.passed
        return "" if p is None else (HOLDS if p else FAILS)


@dataclass
class Check:
    """A claim of the thesis checked on bionav's values; ``passed`` None: not evaluable."""

    rule: str
    passed: bool | None
    detail: str = ""


@dataclass
class Outcome:
    """Everything an item's section shows."""

    rows: list[Row] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)
    figures: list[str] = field(default_factory=list)
    tables: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    #: False when the item needs runs and none of them completed (verdict "not produced" whatever the rows say)
    produced: bool = True

    def outcomes(self) -> list[bool]:
        if not self.produced:
            return []
        got = [r.passed for r in self.rows] + [c.passed for c in self.checks]
        return [g for g in got if g is not None]

    @property
    def verdict(self) -> str:
        return verdict_of(self.outcomes())

    def without_runs(self, n_runs: int) -> Outcome:
        """This outcome for an item none of whose ``n_runs`` runs completed: verdict "not produced".

        Value rows, checks, figures and tables are dropped (they would compare
        nothing or show empty axes); the reasons in ``missing`` and the notes stay.
        """
        missing = self.missing or [f"none of the item's {n_runs} runs completed"]
        return Outcome(notes=list(self.notes), missing=list(missing), produced=False)

    @property
    def score(self) -> tuple[int, int]:
        o = self.outcomes()
        return sum(o), len(o)


def verdict_of(outcomes: Sequence[bool]) -> str:
    """``holds`` / ``partly`` / ``does not hold`` / ``not produced`` (see :data:`VERDICT_RULE`)."""
    if not outcomes:
        return MISSING
    passed = sum(bool(o) for o in outcomes)
    if passed == len(outcomes):
        return HOLDS
    return PARTLY if 2 * passed >= len(outcomes) else FAILS


def fmt(x: Any, digits: int = 4) -> str:
    """A value for tables: integers as they are, other numbers with ``digits`` decimals, else text."""
    if x is None:
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    v = _num(x)
    if v is None:
        return str(x)
    return f"{v:.{digits}f}"
