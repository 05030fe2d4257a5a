"""Figures a reader can compare: one look per method, the paper's values, diverged runs clipped; the PDF's
page numbers and outline."""

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import stats
from matplotlib.colors import to_hex

from conftest import typed

from replication.paths import CONF_DIR, resolve
from replication.report import figures
from replication.report.figures import metric as metric_figures, tracking as tracking_figures
from replication.evidence.published import load_published
from replication.evidence.curves import clip_diverged
from replication.evidence.figures import AttributeMap, figure_spec
from replication.evidence.quantities import QUANTITIES, quantity
from replication.report.figures.style import LABELS, PALETTE, NothingToDraw, axis_label, method_look
from replication.runner.footage import SceneFootage

FOOTAGE = SceneFootage()  # the video the runs saw, as the pages are given it
PUBLISHED = "paper,table,experiment,method,metric,condition,value,unit,note\n" + "\n".join([
    "qmc,1,ungm,PF,rmse,N=100,9.2,,",
    "qmc,1,ungm,PF,rmse,N=500,4.2,,",
    "qmc,1,ungm,QPF,rmse,N=100,2.0,,",  # a method the figure does not draw
    "qmc,1,ungm,PF,time,N=100,5.2,ms,",  # another metric
    "qmc,2,ungm,NQMCPF,rmse,,3.3,,N not stated",  # placed by paper_x
])


@pytest.fixture
def drawn(keep_figures):
    """The figures drawn, as matplotlib Figures (instead of PNG files)."""
    return keep_figures(metric_figures, tracking_figures)


def _scalar_records(values: dict[tuple[str, str], list[float]]) -> pd.DataFrame:
    return typed(pd.DataFrame([{"method": m, "condition": c, "repetition": r, "rmse": v}
                               for (m, c), runs in values.items() for r, v in enumerate(runs)]))


def _tracking_records(curves: dict[str, list[list[float]]]) -> pd.DataFrame:
    return typed(pd.DataFrame([{"method": m, "condition": "scene=a", "repetition": r,
                                "per_frame": {"cle": [None, *run]}}
                               for m, runs in curves.items() for r, run in enumerate(runs)]))


def _lines(fig, label: str) -> list:
    """The drawn lines whose legend label starts with ``label`` (an error-bar series by its data line)."""
    lines = [(line.get_label(), line) for ax in fig.axes for line in ax.get_lines()]
    lines += [(c.get_label(), c.lines[0]) for ax in fig.axes for c in ax.containers]
    return [line for name, line in lines if name.startswith(label)]


def _label(fig, label: str) -> str:
    return next(t.get_text() for ax in fig.axes for t in ax.get_legend().get_texts() if t.get_text().startswith(label))


def test_every_method_of_the_configs_has_a_look_of_its_own(make_cfg):
    """A method's look (its filter's, with its own look: over it) is the same in every shipped experiment that
    has it and no other method's; a user's own method that asks for none takes a spare one, stable, and
    unlike every other method's of its experiment."""
    from omegaconf import OmegaConf

    from replication.paths import experiment_names

    looks: dict[str, set] = {}
    for name in experiment_names():
        experiment = OmegaConf.to_container(make_cfg(name).experiment, resolve=True)
        for method in experiment.get("methods") or {}:
            looks.setdefault(method, set()).add(method_look(experiment, method))
    assert len(looks) >= 40 and all(len(found) == 1 for found in looks.values()), looks
    shipped = [look for found in looks.values() for look in found]
    assert len(set(shipped)) == len(shipped) and {look.colour for look in shipped} <= set(PALETTE)
    mine = {"methods": {"PF": {"filter": "bootstrap"}, "my-filter": {}}}
    own = method_look(mine, "my-filter")
    assert own == method_look(mine, "my-filter") and own != method_look(mine, "PF") and own.colour in PALETTE


@pytest.mark.parametrize("look, said", [
    ("{colour: pink}", "experiment.methods.PF.look: unknown colour 'pink'; known colours: black, blue, green, "
                       "orange, purple, sky, vermillion, yellow"),
    ("{colour: sky, line: dotted}", "experiment.methods.PF.look: unknown line 'dotted'; known lines: '-', '--', "
                                    "'-.', ':'"),
    ("{colour: sky, width: 2}", "experiment.methods.PF.look: unknown part 'width' of a look; a look has colour, "
                                "line, marker"),
])
def test_a_look_no_figure_can_draw_is_one_line_before_any_run(make_cfg, look, said):
    from replication.errors import ConfigError
    from replication.runner.validate import prepare

    with pytest.raises(ConfigError) as error:
        prepare(make_cfg("hspf_ungm", "scale=quick", f"+experiment.methods.PF.look={look}"))
    assert str(error.value) == said


def test_a_look_is_no_part_of_a_run(make_cfg):
    from replication.runner.config import expand

    plain, drawn = (expand(make_cfg("hspf_ungm", "scale=quick", *extra))
                    for extra in ((), ("+experiment.methods.PF.look={colour: sky, marker: s}",)))
    assert [run.key for run in plain] == [run.key for run in drawn]
    assert all("look" not in run.method_params for run in drawn)


def test_a_method_looks_the_same_on_figures_of_two_experiments(drawn, tmp_path):
    ungm = {"paper": "qmc", "methods": {"PF": {"label": "PF (bootstrap)", "filter": "bootstrap"},
                                        "grid": {"filter": "point_mass"}}}
    tracking = {"paper": "trk", "methods": {"ISM-PF": {"filter": "ism"}, "PF": {"label": "PF", "filter": "bootstrap"}}}
    rng = np.random.default_rng(0)
    figures.draw(_scalar_records({("PF", f"N={n}"): list(rng.uniform(4, 5, 5)) for n in (100, 500)}
                                 | {("grid", ""): [4.0, 4.1]}),
                 {"name": "f", "kind": "metric_vs_condition", "metric": "rmse", "x": "N"}, ungm, tmp_path / "a.png", footage=FOOTAGE)
    figures.draw(_tracking_records({"ISM-PF": rng.uniform(0, 5, (4, 30)).tolist(),
                                    "PF": rng.uniform(0, 5, (4, 30)).tolist()}),
                 {"name": "f", "kind": "per_frame_curve", "series": "cle"}, tracking, tmp_path / "b.png", footage=FOOTAGE)
    pf = [_lines(fig, "PF")[0] for fig in drawn]
    assert {to_hex(line.get_color()) for line in pf} == {method_look(ungm, "PF").colour.lower()} == {"#0072b2"}
    assert {line.get_marker() for line in pf} == {method_look(tracking, "PF").marker}
    assert to_hex(_lines(drawn[1], "ISM-PF")[0].get_color()) == method_look(tracking, "ISM-PF").colour.lower()
    assert to_hex(_lines(drawn[0], "grid")[0].get_color()) == method_look(ungm, "grid").colour
    assert drawn[0].axes[0].get_xlabel() == "number of particles N"
    assert drawn[1].axes[0].get_ylabel() == "centre location error (px)"


def test_axis_labels_read_in_words_with_the_raw_name_as_fallback():
    assert axis_label("ms_per_step") == "time per step (ms)"
    assert axis_label("correct_frames[iou>=0.5]") == "share of frames with IoU ≥ 0.5"
    assert axis_label("my_metric") == "my_metric" and axis_label("my_metric[x>1]") == "my_metric[x>1]"
    # one vocabulary: a metric's words are the tables' and claims' (evidence.quantities), rules read there too
    assert not set(LABELS) & set(QUANTITIES) and axis_label("mean_ess") == quantity("mean_ess").label
    assert axis_label("tracked_to_end[cle<=20]") == quantity("tracked_to_end[cle<=20]").label == \
        "runs tracked to the end (centre error ≤ 20 px)"
    assert axis_label("N") == "number of particles N"


def test_the_papers_values_are_hollow_diamonds_at_their_condition(drawn, tmp_path):
    csv = tmp_path / "published.csv"
    csv.write_text(PUBLISHED)
    experiment = {"paper": "qmc", "methods": {"PF": {"filter": "bootstrap"}, "NQMCPF": {"filter": "nqmcpf"}}}
    records = _scalar_records({(m, f"N={n}"): [4.0, 4.5, 5.0] for m in ("PF", "NQMCPF") for n in (100, 200, 500)})
    spec = {"name": "f", "kind": "metric_vs_condition", "metric": "rmse", "x": "N", "paper_table": ["1", "2"],
            "paper_x": {"ungm": 200}}
    figures.draw(records, spec, experiment, tmp_path / "f.png", published=load_published(str(csv)), footage=FOOTAGE)
    paper = {to_hex(line.get_markeredgecolor()): (list(line.get_xdata()), list(line.get_ydata()))
             for line in _lines(drawn[0], "paper")}
    assert paper == {method_look(experiment, "PF").colour.lower(): ([100, 500], [9.2, 4.2]),
                     method_look(experiment, "NQMCPF").colour.lower(): ([200], [3.3])}
    assert all(line.get_marker() == "D" and line.get_markerfacecolor() == "none" for line in _lines(drawn[0], "paper"))
    legend = [t.get_text() for t in drawn[0].axes[0].get_legend().get_texts()]
    assert legend.count("paper") == 1
    figures.draw(records, {k: v for k, v in spec.items() if k != "paper_table"}, experiment, tmp_path / "g.png",
                 published=load_published(str(csv)), footage=FOOTAGE)
    assert not _lines(drawn[1], "paper")  # no paper_table: no diamonds


def test_the_configs_paper_table_puts_table_1_on_the_rmse_figure(drawn, tmp_path):
    published = resolve("../shared/reference/published_values.csv")
    if not published.exists():
        pytest.skip("../shared is not beside the project")
    config = yaml.safe_load((CONF_DIR / "experiment" / "gps_qmcpf.yaml").read_text())
    spec = next(s for s in config["report"]["figures"] if s["name"] == "rmse_vs_n")
    records = _scalar_records({(m, f"N={n}"): [4.0, 4.5] for m in config["methods"] if m != "grid"
                               for n in (100, 200, 500)})
    figures.draw(records, spec, config, tmp_path / "rmse.png", published=load_published(str(published)), footage=FOOTAGE)
    points = sorted((x, y) for line in _lines(drawn[0], "paper") for x, y in zip(line.get_xdata(), line.get_ydata()))
    assert len(points) == 12 and (500, 1.597) in points  # Table 1: four methods at N = 100, 200, 500


def test_clip_diverged_puts_non_finite_and_huge_values_at_the_level():
    values, diverged = clip_diverged([[1.0, 2.0], [np.inf, 1.0], [-50.0, 1.0], [1.0, np.nan]], level=10.0)
    assert values.tolist() == [[1.0, 2.0], [10.0, 1.0], [-10.0, 1.0], [1.0, 10.0]]
    assert diverged.tolist() == [False, True, True, True]
    values, diverged = clip_diverged([1.0, np.inf], level=None)  # no level: left out, still counted
    assert np.isnan(values[1]) and diverged.tolist() == [False, True]


def test_diverged_runs_are_clipped_and_counted_on_per_frame_curves(drawn, tmp_path):
    rng = np.random.default_rng(1)
    good = rng.uniform(1, 3, (10, 40))
    good[2, 20:] = 1e6  # blown up
    good[5, 7] = np.inf
    lost = rng.uniform(80, 120, (5, 40))  # a method that loses the target every run: not a divergence
    experiment = {"methods": {"PF": {"label": "PF"}, "MIL": {"label": "MIL"}}}
    figures.draw(_tracking_records({"PF": good.tolist(), "MIL": lost.tolist()}),
                 {"name": "f", "kind": "per_frame_curve", "series": "cle"}, experiment, tmp_path / "c.png", footage=FOOTAGE)
    pf, mil = _lines(drawn[0], "PF")[0], _lines(drawn[0], "MIL")[0]
    assert _label(drawn[0], "PF") == "PF (2 of 10 runs diverged, clipped)" and _label(drawn[0], "MIL") == "MIL"
    assert max(pf.get_ydata()) < max(mil.get_ydata()) * 10 / 2  # the blown-up run no longer dominates


def test_diverged_runs_are_clipped_and_counted_on_metric_curves(drawn, tmp_path):
    experiment = {"methods": {"PF": {"label": "PF"}}}
    records = _scalar_records({("PF", "N=100"): [4.0, 5.0, 1e9, 4.5, 5.5], ("PF", "N=500"): [3.0, np.inf, 3.2, 3.1]})
    figures.draw(records, {"name": "f", "kind": "metric_vs_condition", "metric": "rmse", "x": "N"}, experiment,
                 tmp_path / "m.png", footage=FOOTAGE)
    line = _lines(drawn[0], "PF")[0]
    assert _label(drawn[0], "PF") == "PF (2 of 9 runs diverged, clipped)"
    assert line.get_ydata()[0] < 10 * 5.0  # the mean with the 1e9 run counted at 10 times the median
    assert np.isfinite(np.asarray(line.get_ydata(), dtype=float)).all()


def test_the_pdf_numbers_its_pages_and_has_an_outline(tmp_path):
    import matplotlib.pyplot as plt
    import pypdf

    from replication.report import pdf

    png = tmp_path / "f.png"
    fig = plt.figure(figsize=(4, 3))
    fig.savefig(png)
    plt.close(fig)
    path = tmp_path / "book.pdf"
    long = pd.DataFrame({"method": [f"method {i}" for i in range(150)], "value": range(150)})
    with pdf._Book(path) as book:
        pdf._table_pages(book, "Experiment A", long, subtitle="Table 1: a long one", font=pdf.TABLE_FONT)
        pdf._figure_page(book, "Experiment A", "Figure 1", png)
        pdf._figure_page(book, "Experiment B", "Figure 2", png)
    pdf._outline(path, book.marks)
    reader = pypdf.PdfReader(str(path))
    n = len(reader.pages)
    assert n >= 4  # the table takes at least two pages
    for k, page in enumerate(reader.pages, start=1):
        assert f"page {k}" in page.extract_text()
    outline = reader.outline
    sections = [item for item in outline if not isinstance(item, list)]
    assert [s.title for s in sections] == ["Experiment A", "Experiment B"]
    entries = [[(e.title, reader.get_destination_page_number(e)) for e in item] for item in outline
               if isinstance(item, list)]
    assert entries == [[("Table 1: a long one", 0), ("Figure 1", n - 2)], [("Figure 2", n - 1)]]
    assert reader.get_destination_page_number(sections[1]) == n - 1


def test_a_figure_limited_to_conditions_draws_only_their_runs(tmp_path, monkeypatch):
    records = typed(pd.DataFrame({"condition": ["scene=a", "scene=b"], "method": ["M", "M"]}))
    with pytest.raises(NothingToDraw, match="no runs at conditions"):  # the page leaves it out, and says so
        figures.draw(records, {"name": "f", "kind": "metric_vs_condition", "metric": "rmse", "x": "N",
                               "conditions": [{"scene": "c"}]}, {},
                     tmp_path / "f.png", footage=FOOTAGE)
    no_strip = typed(pd.DataFrame({"condition": ["scene=x"], "method": ["M"], "repetition": [0], "strip": [None]}))
    with pytest.raises(NothingToDraw, match="no run recorded a strip"):  # no run on the 3123 scene
        tracking_figures.mode_strip(no_strip, figure_spec({"name": "modes_3123", "kind": "mode_strip"}), {},
                                    tmp_path / "m.png", footage=FOOTAGE)
    with pytest.raises(NothingToDraw, match="drawn from each run's strip, per_frame, which these records do not"):
        figures.draw(no_strip.drop(columns="strip"), {"name": "m", "kind": "mode_strip"}, {}, tmp_path / "m.png", footage=FOOTAGE)
    seen = []
    monkeypatch.setitem(figures.DRAWINGS, AttributeMap,
                        lambda r, s, e, p, footage: seen.append(sorted(r["condition"])) or p)
    figures.draw(records, {"name": "g", "kind": "attribute_map", "conditions": [{"scene": "b"}]}, {}, tmp_path / "g.png", footage=FOOTAGE)
    assert seen == [["scene=b"]]


def test_the_encounter_strip_marks_a_swap_where_the_per_identity_error_jumps(drawn, monkeypatch, tmp_path):
    """Two balls cross; method A's estimates follow each other's ball from frame 16 on, B's stay.  A's strip
    has one red tick at frame 16 on the one pair that met, B's none; the off-image curve counts nothing."""
    from types import SimpleNamespace

    frames = np.arange(30)
    truth = np.zeros((30, 2, 4))
    truth[..., 2:] = 20
    truth[:, 0, 0], truth[:, 1, 0], truth[..., 1] = frames * 3.0, 90 - frames * 3.0, 50
    swapped = truth.copy()
    swapped[16:] = truth[16:, ::-1]

    class Seen(SceneFootage):  # every run saw the hand-made video (the figure and the off-image curve's table)
        def seen(self, experiment, runs):
            return SimpleNamespace(truth=truth, size=(200, 100))
    records = typed(pd.DataFrame([{"method": m, "condition": "scene=a", "repetition": 0,
                                   "per_frame": {"box": boxes.tolist(), "targets": [0, 1]}}
                                  for m, boxes in (("A", swapped), ("B", truth))]))
    experiment = {"methods": {"A": {}, "B": {}}}
    figures.draw(records, {"name": "e", "kind": "encounter_strip", "distance": 20.0}, experiment, tmp_path / "e.png",
                 footage=Seen())
    fig = drawn[-1]
    strips = fig.axes[1::2]
    ticks = [[line.get_xdata()[0] for line in ax.get_lines() if to_hex(line.get_color()) == to_hex("C3")]
             for ax in strips]
    assert ticks == [[16, 16], []]  # both estimates of the pair start on the other ball at frame 16
    per_identity = next(line for line in fig.axes[0].get_lines() if line.get_label() == "per identity")
    assert per_identity.get_ydata()[15] < 20 < per_identity.get_ydata()[20]
    figures.draw(records, {"name": "o", "kind": "outside_curve"}, experiment, tmp_path / "o.png", footage=Seen())
    assert all((line.get_ydata() == 0).all() for line in drawn[-1].axes[0].get_lines())


def test_error_against_cost_puts_each_condition_at_its_mean_cost_and_leaves_out_what_did_no_work(keep_figures,
                                                                                               tmp_path):
    from replication.report.figures import cost as cost_figures

    drawn = keep_figures(cost_figures)
    rows = [("PF", "N=100", 100, 0.1, [5.0, 5.2, 4.8]), ("PF", "N=500", 500, 0.4, [4.0, 4.1, 3.9]),
            ("HSPF", "N=100", 2300, 1.8, [4.9, 5.1, 4.7]), ("SORT", "", 0, 0.01, [6.0, 6.0, 6.0])]
    records = typed(pd.DataFrame([{"method": m, "condition": c, "repetition": r, "rmse": v,
                                   "evaluations_per_step": e, "ms_per_step": s * (1 + 0.01 * r)}
                                  for m, c, e, s, values in rows for r, v in enumerate(values)]))
    experiment = {"methods": {}}
    figures.draw(records, {"name": "f", "kind": "metric_vs_cost", "metric": "rmse"}, experiment, tmp_path / "c.png", footage=FOOTAGE)
    work, time = drawn[0].axes[:2]
    pf = next(line for line in work.get_lines() if line.get_label() == "PF")  # two budgets: a line and its band
    assert pf.get_xdata().tolist() == [100, 500] and pf.get_ydata() == pytest.approx([5.0, 4.0])  # ordered by cost
    (band,) = work.collections[:1]
    low, high = band.get_paths()[0].vertices[:, 1].min(), band.get_paths()[0].vertices[:, 1].max()
    assert low == pytest.approx(4.0 - stats.t.ppf(0.975, 2) * 0.1 / np.sqrt(3)) and high > 5.0  # the 95% t band
    assert [c.get_label() for c in work.containers] == ["HSPF"]  # one budget: a point with its interval
    labels = [line.get_label() for line in work.get_lines() if not line.get_label().startswith("_")]
    assert "SORT" not in labels + [c.get_label() for c in work.containers]  # SORT counted no work
    hspf = next(c for c in time.containers if c.get_label() == "HSPF").lines[0]
    assert hspf.get_xdata()[0] == pytest.approx(1.8 * 1.01)  # the median time over runs
    with pytest.raises(ValueError, match="the runs have no"):
        figures.draw(records, {"name": "f", "kind": "metric_vs_cost", "metric": "mota"}, experiment, tmp_path / "d.png", footage=FOOTAGE)


def test_error_against_cost_paired_to_a_reference_draws_run_by_run_differences(keep_figures, tmp_path):
    """``paired_to``: each run's metric minus the reference method's on the same data and repetition, with
    the paired t interval; the reference is not drawn."""
    from replication.report.figures import cost as cost_figures

    drawn = keep_figures(cost_figures)
    base = np.array([4.0, 6.0, 5.0])  # the data's spread, which pairing cancels
    rows = [("grid", "", 0, base), ("PF", "N=100", 100, base + [0.3, 0.5, 0.4]),
            ("PF", "N=500", 500, base + [0.1, 0.1, 0.1 + 1e-9])]
    records = typed(pd.DataFrame([{"method": m, "condition": c, "data_condition": "", "repetition": r, "rmse": v,
                                   "evaluations_per_step": e, "ms_per_step": 0.1 + e / 1e3}
                                  for m, c, e, values in rows for r, v in enumerate(values)]))
    figures.draw(records, {"name": "f", "kind": "metric_vs_cost", "metric": "rmse", "paired_to": "grid"}, {"methods": {}},
                 tmp_path / "p.png", footage=FOOTAGE)
    work = drawn[0].axes[0]
    (pf,) = [line for line in work.get_lines() if line.get_label() == "PF"]
    assert pf.get_ydata() == pytest.approx([0.4, 0.1])
    band = work.collections[0].get_paths()[0].vertices[:, 1]
    half = stats.t.ppf(0.975, 2) * 0.1 / np.sqrt(3)  # the differences 0.3, 0.5, 0.4: sd 0.1
    assert band.max() == pytest.approx(0.4 + half) and band.min() < 0.1 + 1e-6
    assert "grid" not in [line.get_label() for line in work.get_lines()] + [c.get_label() for c in work.containers]
    assert "minus grid's" in work.get_ylabel()
