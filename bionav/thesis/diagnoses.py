"""Why an item does not hold: the diagnoses of ``diagnoses.yaml``, each found by an experiment (issue 44).

A diagnosis names one or more of :data:`KINDS` (a defect of the check, fixed;
the preset's reduction; the statistics; the stand-in; a real disagreement with
the thesis; the thesis contradicting itself), says why in a few sentences with
the measured numbers and points to its evidence: a section of
``docs/thesis.md`` with the commands that reproduce it. The report prints it
beside every verdict other than *holds*; an item that does not hold and has no
diagnosis says so.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

import yaml

#: the kinds of reason, in words for the report
KINDS = {
    "check": "a defect of the check (fixed)",
    "reduction": "the preset's reduction",
    "statistics": "the statistics",
    "stand-in": "the stand-in",
    "disagreement": "a real disagreement with the thesis",
    "thesis": "the thesis contradicts itself",
}

#: where the evidence lives (``evidence`` is an anchor of this file)
EVIDENCE_DOC = "docs/thesis.md"


@dataclass(frozen=True)
class Diagnosis:
    """Why one item does not hold.

    Attributes
    ----------
    item : str
        Item id (``fig5_6``).
    kinds : tuple of str
        Keys of :data:`KINDS`, the main reason first.
    why : str
        The reason in one or two sentences, with the measured numbers.
    evidence : str
        Anchor of the section of ``docs/thesis.md`` that holds the evidence and the commands reproducing it.
    preset : str
        The preset whose verdict was diagnosed.
    """

    item: str
    kinds: tuple[str, ...]
    why: str
    evidence: str
    preset: str = "quick"

    @property
    def kind_words(self) -> str:
        return "; ".join(KINDS[k] for k in self.kinds)

    def line(self) -> str:
        """The reason as one line of text (``kind: why``)."""
        return f"{self.kind_words}: {self.why}"


@lru_cache(maxsize=1)
def load_diagnoses() -> dict[str, Diagnosis]:
    """Every diagnosis of ``diagnoses.yaml``, keyed by item id (validated: known kinds, non-empty reasons)."""
    text = resources.files("bionav.thesis").joinpath("diagnoses.yaml").read_text(encoding="utf-8")
    raw = yaml.safe_load(text) or {}
    out = {}
    for item_id, d in raw.items():
        kinds = tuple(d.get("kind") or ()) if isinstance(d.get("kind"), list) else (d.get("kind"),)
        if not kinds or any(k not in KINDS for k in kinds) or not d.get("why") or not d.get("evidence"):
            raise ValueError(f"diagnoses.yaml: {item_id} needs kind (one or a list of {', '.join(KINDS)}), why and "
                             "evidence")
        out[item_id] = Diagnosis(item_id, kinds, " ".join(str(d["why"]).split()), str(d["evidence"]),
                                 str(d.get("preset", "quick")))
    return out


def evidence_href(diagnosis: Diagnosis, out: Path) -> str | None:
    """The evidence's address relative to the report directory ``out``; None where bionav's docs are not on disk
    (an installed wheel)."""
    docs = Path(__file__).resolve().parents[2] / EVIDENCE_DOC
    return f"{os.path.relpath(docs, out)}#{diagnosis.evidence}" if docs.is_file() else None


def evidence_link(diagnosis: Diagnosis, out: Path, text: str | None = None) -> str:
    """A Markdown link to the evidence (``text``, default its repository path), or the path where no docs are."""
    target = f"{EVIDENCE_DOC}#{diagnosis.evidence}"
    href = evidence_href(diagnosis, out)
    if href is None:
        return f"{text} (`{target}` in bionav's source)" if text else f"`{target}` (in bionav's source)"
    return f"[{text or target}]({href})"
