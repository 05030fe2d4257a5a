"""One page per sequence an experiment ran: the figures its report spec names in ``sequence_pages``, each
drawn from that sequence's runs alone (a real-video experiment's snapshots, identity timeline and video,
for whichever sequences were run, the user's own included)."""

from pathlib import Path

import pandas as pd

from replication import atomic
from replication.condition import values_of
from replication.evidence.figures import figure_specs
from replication.evidence.footage import Footage
from replication.report.figures import draw
from replication.report.figures.style import NothingToDraw
from replication.report.pages.render import render


def write_sequence_pages(records: pd.DataFrame, experiment: dict, out: Path, footage: Footage) -> list[dict]:
    """Write ``<out>/sequences/<scene>.html`` for each scene in ``records``; return one link per page
    (``scene``, ``link``, ``what``: the sequence's name); ``footage``: the video the runs saw."""
    spec = experiment.get("report", {})
    names = spec.get("sequence_pages", [])
    by_name = {figure.name: figure for figure in figure_specs(experiment)}
    unknown = sorted(set(names) - set(by_name))
    if unknown:
        raise ValueError(f"report.sequence_pages names no figure of the report: {unknown}; figures: {sorted(by_name)}")
    scenes = values_of(records, "scene")
    links = []
    for scene in [s for s in dict.fromkeys(scenes) if s is not None] if names else []:
        folder = out / "sequences" / scene
        folder.mkdir(parents=True, exist_ok=True)
        runs, sections = records[scenes == scene], []
        for name in names:
            figure = by_name[name].on_scene(scene)
            try:
                draw(runs, figure, experiment, folder / f"{name}.png", footage=footage)
            except NothingToDraw:
                continue
            sections.append({"title": figure.title, "figure": f"{scene}/{name}.png", "table": None,
                             "link": f"{scene}/{figure.linked}" if figure.linked else None})
        what = experiment["scenes"][scene].get("name", scene)
        page = out / "sequences" / f"{scene}.html"
        atomic.write_text(page, render("sections.html.j2", title=f"{experiment['name']}: {what}",
                                       up="../index.html", up_label=experiment["name"],
                                       meta=f"{len(runs)} runs on {what} (scene {scene})", sections=sections))
        links.append({"scene": scene, "link": f"sequences/{scene}.html", "what": what})
    return links
