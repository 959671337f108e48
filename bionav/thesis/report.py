"""Writing the thesis report: ``report.md``, ``report.html`` (figures inline) and ``items.csv``."""

from __future__ import annotations

import base64
import html
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from bionav.files import write_csv_atomic
from bionav.thesis.diagnoses import EVIDENCE_DOC, Diagnosis, evidence_link
from bionav.thesis.outcome import FAILS, MISSING, PARTLY, VERDICT_RULE, Outcome, fmt
from bionav.thesis.presets import Preset

CSV_COLUMNS = ("item", "label", "quantity", "thesis", "bionav", "difference", "tolerance", "verdict", "level", "why",
               "evidence")


@dataclass
class Section:
    """One item's part of the report."""

    id: str
    label: str
    title: str
    source: str
    rule: str
    outcome: Outcome
    runs: list  # RunResult
    claims: list[str]
    #: why the item does not hold (bionav/thesis/diagnoses.yaml); shown for the verdicts partly and does not hold
    diagnosis: Diagnosis | None = None

    @property
    def needs_why(self) -> bool:
        return self.outcome.verdict in (PARTLY, FAILS)

    def why(self) -> str:
        """The reason for the verdict in words ("" when the item holds or was not produced)."""
        if not self.needs_why:
            return ""
        if self.diagnosis is None:
            return "not diagnosed (no entry in bionav/thesis/diagnoses.yaml)"
        return self.diagnosis.line()


def csv_rows(sections: Sequence[Section]) -> list[dict[str, str]]:
    """items.csv: one row per item (its verdict), per check and per value."""
    rows = []
    for s in sections:
        o = s.outcome
        passed, total = o.score
        evidence = f"{EVIDENCE_DOC}#{s.diagnosis.evidence}" if s.needs_why and s.diagnosis else ""
        rows.append({"item": s.id, "label": s.label, "quantity": "(item verdict)", "thesis": "",
                     "bionav": f"{passed}/{total} checks pass", "difference": "", "tolerance": "",
                     "verdict": o.verdict, "level": "item", "why": s.why(), "evidence": evidence})
        for c in o.checks:
            rows.append({"item": s.id, "label": s.label, "quantity": c.rule, "thesis": "claim", "bionav": c.detail,
                         "difference": "", "tolerance": "",
                         "verdict": "" if c.passed is None else ("holds" if c.passed else "does not hold"), "level": "check"})
        for r in o.rows:
            rows.append({"item": s.id, "label": s.label, "quantity": r.quantity,
                         "thesis": "" if r.thesis is None else fmt(r.thesis, 6),
                         "bionav": "" if r.bionav is None else fmt(r.bionav, 6),
                         "difference": "" if r.difference is None else fmt(r.difference, 6),
                         "tolerance": "" if r.tolerance is None else fmt(r.tolerance, 6),
                         "verdict": r.verdict, "level": "value"})
    return rows


def write_csv(path: Path, sections: Sequence[Section]) -> None:
    """Write ``items.csv``: one row per item, check and value (:data:`CSV_COLUMNS`), atomically."""
    write_csv_atomic(path, CSV_COLUMNS, ([row.get(c, "") for c in CSV_COLUMNS] for row in csv_rows(sections)))


def verdict_counts(sections: Sequence[Section]) -> Counter:
    return Counter(s.outcome.verdict for s in sections)


def _run_lines(section: Section, out: Path) -> list[str]:
    lines = []
    for r in section.runs:
        where = "" if r.dir is None else str(Path(r.dir).relative_to(out)) if str(r.dir).startswith(str(out)) else str(r.dir)
        state = "completed" if r.ok else f"not completed: {r.error}"
        t = "" if r.seconds is None else f", {r.seconds:.0f} s wall" + (
            "" if r.cpu_seconds is None else f", {r.cpu_seconds:.0f} s CPU")
        reused = ", reused" if r.reused else ""
        lines.append(f"- `python -m bionav {'-m ' if r.spec.multirun else ''}{' '.join(r.spec.overrides)}` "
                     f"-> `{where}` ({state}{t}{reused})")
    return lines


_CODE_SPAN = re.compile(r"(`[^`]*`)")


def md_text(text: object) -> str:
    """Plain text for Markdown: ``*`` escaped outside code spans, so ``AAE*`` keeps its asterisk.

    Names such as ``AAE*``, ``MAE*`` and ``RR*`` (thesis 3.2) would otherwise
    open and close emphasis (``AAE*, MAE*`` renders as "AAE, MAE" in italics).
    """
    parts = _CODE_SPAN.split(str(text))
    return "".join(p if p.startswith("`") and p.endswith("`") and len(p) > 1 else p.replace("*", "\\*") for p in parts)


def _cell(text: str) -> str:
    """Text for a Markdown table cell (asterisks and pipes escaped, one line)."""
    return md_text(text).replace("|", "\\|").replace("\n", " ")


def section_markdown(s: Section, out: Path) -> str:
    o = s.outcome
    passed, total = o.score
    verdict = (f"*Verdict:* **{o.verdict}** ({passed} of {total} checks pass).  " if o.produced else
               f"*Verdict:* **{o.verdict}** (none of this item's runs completed; nothing was compared).  ")
    md = [f"## {md_text(_heading(s))}", "", f"*Source:* {md_text(s.source)}.  ", verdict,
          *_why_lines(s, out), f"*Rule:* {md_text(s.rule)}.", ""]
    if s.claims:
        md += ["The thesis claims:", *[f"- {md_text(c)}" for c in s.claims], ""]
    if o.missing:
        md += ["**Not produced / incomplete:**", *[f"- {md_text(m)}" for m in o.missing], ""]
    if o.rows:
        notes = any(r.note for r in o.rows)  # e.g. the per-draw values of table 5.3 on the stand-ins
        md += ["| quantity | thesis | bionav | difference | tolerance | verdict |" + (" note |" if notes else ""),
               "|---|---|---|---|---|---|" + ("---|" if notes else "")]
        md += [f"| {_cell(r.quantity)} | {_cell(fmt(r.thesis))} | {_cell(fmt(r.bionav))} | {fmt(r.difference)} | "
               f"{'' if r.tolerance is None else fmt(r.tolerance)} | {r.verdict} |"
               + (f" {_cell(r.note)} |" if notes else "") for r in o.rows]
        md.append("")
    if o.checks:
        md += ["| check | result | detail |", "|---|---|---|"]
        md += [f"| {_cell(c.rule)} | {'n/a' if c.passed is None else ('pass' if c.passed else 'fail')} | {_cell(c.detail)} |"
               for c in o.checks]
        md.append("")
    for n in o.notes:
        md.append(f"*Note:* {md_text(n)}  ")
    if o.tables:
        md += ["", "Tables: " + ", ".join(f"[{t}]({t})" for t in o.tables)]
    md.append("")
    for fig in o.figures if o.produced else ():
        md += [f"![{s.label}: {fig}]({fig})", ""]
    runs = _run_lines(s, out)
    if runs:
        md += ["<details><summary>runs</summary>", "", *runs, "", "</details>", ""]
    return "\n".join(md)


def _why_lines(s: Section, out: Path) -> list[str]:
    """The section's "Why" line (verdicts partly and does not hold) with the link to its evidence."""
    if not s.needs_why:
        return []
    d = s.diagnosis
    if d is None:
        return [f"*Why:* {md_text(s.why())}.  "]
    return [f"*Why ({md_text(d.kind_words)}; diagnosed on the {d.preset} preset):* {md_text(d.why)} "
            f"Evidence: {evidence_link(d, out)}.  "]


def _why_cell(s: Section, out: Path) -> str:
    """The summary table's reason: its kinds, linked to the evidence."""
    if not s.needs_why:
        return ""
    return "not diagnosed" if s.diagnosis is None else evidence_link(s.diagnosis, out, md_text(s.diagnosis.kind_words))


def report_markdown(sections: Sequence[Section], *, preset: Preset, out: Path, wall_s: float, command: str,
                    cpu_s: float | None = None, machine: str = "") -> str:
    counts = verdict_counts(sections)
    head = [
        "# The thesis, reproduced by bionav", "",
        f"Command: `{command}`  ", f"Preset: **{preset.name}** ({md_text(preset.summary)}).  ",
        f"Wall time of this invocation: {wall_s:.0f} s" + (f" (CPU of the runs it executed: {cpu_s:.0f} s)" if cpu_s else "")
        + (f"; machine: {machine}" if machine else "") + ".",
        "",
        "bionav runs on synthetic stand-ins of the thesis' databases, sensors and scenes; many verdicts are honestly "
        "'does not hold' because the stand-ins are not calibrated to the thesis' environments.", "",
        VERDICT_RULE, "",
        "| verdict | items |", "|---|---|",
        *[f"| {v} | {counts.get(v, 0)} |" for v in ("holds", "partly", "does not hold", MISSING)], "",
    ]
    if preset.reductions:
        head += ["Reductions of this preset against the thesis:", *[f"- {md_text(r)}" for r in preset.reductions], ""]
    head += ["| item | verdict | checks | why |", "|---|---|---|---|"]
    head += [f"| [{s.label}](#{_anchor(s)}) | {s.outcome.verdict} | "
             + (f"{s.outcome.score[0]}/{s.outcome.score[1]} |" if s.outcome.produced else "no run completed |")
             + f" {_why_cell(s, out)} |" for s in sections]
    head.append("")
    return "\n".join(head + [section_markdown(s, out) for s in sections])


def _heading(s: Section) -> str:
    return s.title if s.title.lower().startswith(s.label.split(" /")[0].lower()) else f"{s.label}: {s.title}"


def _anchor(s: Section) -> str:
    text = _heading(s).lower()
    return re.sub(r"[^a-z0-9 -]", "", text).replace(" ", "-")


def markdown_to_html(md: str, out: Path) -> str:
    """A small Markdown renderer for the report (headings, tables, lists, images inline as base64)."""
    body, table, in_list = [], [], False

    def inline(text: str) -> str:
        # code spans verbatim; elsewhere "\*" is a literal asterisk, "**b**" bold, "*i*" italics, links
        pieces = []
        for part in _CODE_SPAN.split(text):
            if part.startswith("`") and part.endswith("`") and len(part) > 1:
                pieces.append(f"<code>{html.escape(part[1:-1], quote=False)}</code>")
                continue
            t = html.escape(part, quote=False).replace("\\*", "\x00")
            t = re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", t)
            t = re.sub(r"\*([^*]+)\*", r"<i>\1</i>", t)
            t = re.sub(r"\[([^\]]+)\]\(#([^)]+)\)", r'<a href="#\2">\1</a>', t)
            t = re.sub(r"\[([^\]]+)\]\(([^)]+)\)", r'<a href="\2">\1</a>', t)
            pieces.append(t.replace("\x00", "*"))
        return "".join(pieces)

    def flush_table():
        if table:
            rows = [r for r in table if not re.match(r"^\|[-| ]+\|$", r)]
            cells = [[c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", r.strip()[1:-1])] for r in rows]
            h = "".join(f"<th>{inline(c)}</th>" for c in cells[0])
            b = "".join("<tr>" + "".join(f"<td>{inline(c)}</td>" for c in row) + "</tr>" for row in cells[1:])
            body.append(f"<table><tr>{h}</tr>{b}</table>")
            table.clear()

    for line in md.splitlines():
        if line.startswith("|"):
            table.append(line)
            continue
        flush_table()
        if in_list and not line.startswith("- "):
            body.append("</ul>")
            in_list = False
        m = re.match(r"^!\[([^\]]*)\]\(([^)]+)\)$", line)
        if m:
            path = out / m.group(2)
            if path.is_file():
                data = base64.b64encode(path.read_bytes()).decode()
                body.append(f'<figure><img alt="{html.escape(m.group(1))}" src="data:image/png;base64,{data}">'
                            f"<figcaption>{html.escape(m.group(2))}</figcaption></figure>")
            continue
        if line.startswith("#"):
            level = len(line) - len(line.lstrip("#"))
            text = line[level:].strip()
            anchor = re.sub(r"[^a-z0-9 -]", "", text.replace("\\*", "").lower()).replace(" ", "-")
            body.append(f'<h{level} id="{anchor}">{inline(text)}</h{level}>')
        elif line.startswith("- "):
            if not in_list:
                body.append("<ul>")
                in_list = True
            body.append(f"<li>{inline(line[2:])}</li>")
        elif line.startswith("<details") or line.startswith("</details"):
            body.append(line)
        elif line.strip():
            body.append(f"<p>{inline(line)}</p>")
    flush_table()
    if in_list:
        body.append("</ul>")
    style = ("body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em}table{border-collapse:collapse;"
             "font-size:85%}td,th{border:1px solid #ccc;padding:2px 6px}img{max-width:100%}code{font-size:85%}")
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>bionav: the thesis reproduced</title>"
            f"<style>{style}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n")
