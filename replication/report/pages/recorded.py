"""The paper-scale record on the report's index: where its runs came from, whether this code made them,
whether this machine computed any of them again, and its verdicts beside this machine's.

``python -m replication.report source=record`` draws the record's pages into ``<reports>/record/`` and
writes :data:`STATUS` there (:func:`write_status`); ``pf-replicate verify against=store`` writes
:data:`~replication.record.manifest.RECOMPUTED` beside it.  :func:`recorded` reads both for the index.
"""

import json
from pathlib import Path

from replication import atomic
from replication.evidence.claims import Paper
from replication.evidence.scorecard import ClaimRow, claim_rows
from replication.evidence.summary import load_summaries
from replication.record.manifest import PAGES, RECOMPUTED, Manifest

STATUS = "status.json"


def write_status(out: Path, manifest: Manifest, stale: dict[str, int], designed: dict[str, int],
                 drawn_from: dict[str, str], profile: dict | None = None) -> Path:
    """``<out>/status.json``: the manifest's account of the runs drawn (their count, CPU time, commits,
    dates, the size of their files, the machines and libraries that made them), per experiment what it took
    and what its previous recording took (``before``), how many of its
    recorded runs other code or settings than this checkout's made (``stale``), per multiverse how many
    universes its design has beside those recorded (``designed``; 0 for an experiment), and what the pages were
    drawn from (``drawn_from``: the digests of the record, the configs, the published values and the
    drawing code, so that pages drawn from other inputs are drawn again before findings are rendered), and
    the record's ``profile`` (:func:`~replication.record.manifest.read_profile`) as it is."""
    entries = {name: manifest.experiments[name] for name in stale}
    status = {
        "drawn_from": drawn_from,
        "runs": sum(e.runs for e in entries.values()),
        "failed": sum(e.failed for e in entries.values()),
        "cpu_hours": round(sum(e.wall_s for e in entries.values()) / 3600, 1),
        "commits": sorted({c[:7] for e in entries.values() for c in e.commits}),
        "megabytes": round(sum(e.bytes for e in entries.values()) / 1e6, 1),
        "machines": sorted({m for e in entries.values() for m in e.machines}),
        "libraries": sorted({lib for e in entries.values() for lib in e.libraries}),
        "first": min((e.first_computed for e in entries.values() if e.first_computed), default=None),
        "last": max((e.last_computed for e in entries.values() if e.last_computed), default=None),
        "experiments": {name: {"runs": entries[name].runs, "stale": n, "universes": entries[name].universes,
                               "designed": designed.get(name, 0),
                               "minutes": entries[name].minutes, "cpu_minutes": round(entries[name].wall_s / 60, 1),
                               "thread_cpu_minutes": entries[name].cpu_s and round(entries[name].cpu_s / 60, 1),
                               "load_1m": entries[name].load_1m, "reference_ms": entries[name].reference_ms,
                               "before": _before(entries[name].before)} for name, n in stale.items()},
        "profile": profile,
    }
    path = out / STATUS
    atomic.write_text(path, json.dumps(status, indent=1) + "\n")
    return path


def _before(before) -> dict | None:
    """What the recording an entry replaced took, as the status shows it (None if it replaced none)."""
    if before is None:
        return None
    return {"minutes": before.minutes, "cpu_minutes": round(before.wall_s / 60, 1),
            "commits": sorted({c[:7] for c in before.commits}), "written": before.written}


def recorded(reports: Path, papers: tuple[Paper, ...]) -> dict | None:
    """What the index shows of the record drawn under ``reports`` (None where none was drawn): its status,
    the experiments other code made, this machine's recomputation, and each claim's recorded row by id."""
    folder = Path(reports) / PAGES
    if not (folder / STATUS).exists():
        return None
    status = json.loads((folder / STATUS).read_text())
    again = json.loads((folder / RECOMPUTED).read_text()) if (folder / RECOMPUTED).exists() else None
    rows: dict[str, ClaimRow] = {row.claim.id: row for paper_rows in
                                 claim_rows(list(papers), load_summaries(folder)).values() for row in paper_rows}
    return {
        **status,
        "stale": {name: e for name, e in status["experiments"].items() if e["stale"]},
        "recomputed": None if again is None else {
            "runs": sum(e["compared"] for e in again.values()),
            **{grade: sum(e[grade] for e in again.values()) for grade in ("identical", "within", "diverged")},
            "largest": max((e["largest"] for e in again.values()), default=0.0),
            "lines": [line for e in again.values() for line in e["lines"]],
            "beyond": [line for e in again.values() for line in e["beyond"]]},
        "claims": rows,
    }
