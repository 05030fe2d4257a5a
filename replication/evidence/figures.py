"""The figure kinds a report spec names, each with its options as typed fields, the per-frame series of a run
it draws from and whether it draws a curve table (``curved``: computed below the report, by
:mod:`replication.runner.curves`, and kept in the record in place of the runs' series).

A figure kind is a frozen dataclass deriving from :class:`FigureSpec`, registered in :data:`FIGURE_KINDS`
under its ``kind`` name by its class keywords (``kind=``, ``reads=``, ``curved=``, ``filmed=``); the config check turns
each ``figures:`` entry into one (:func:`figure_specs`) before any run, so a misspelled option or an unknown
kind is one line naming the file, the figure and the options the kind takes.  The drawing lives in
:mod:`replication.report.figures`, one function per kind (``@draws(TheKind)``).
"""

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

from replication.kinds import Registry
from replication.specs import Spec, kind_named

FIGURE_KINDS: Registry[type["FigureSpec"]] = Registry("figure kind")


@dataclass(frozen=True, kw_only=True)
class FigureSpec(Spec):
    """What every figure names: its file name, its kind, its title, the ``conditions`` whose runs it draws
    (each a mapping of values; none: every run) and the table it is shown ``beside`` (none: with the
    figures)."""

    name: str
    kind: str
    title: str = ""
    conditions: Any = None
    beside: str | None = None

    reads: ClassVar[tuple[str, ...]] = ()  # the per-frame series of each run it draws (per_frame, tracks, strip)
    curved: ClassVar[bool] = False  # it draws a curve table (replication.runner.curves), not the runs
    filmed: ClassVar[bool] = False  # it is drawn on the video the runs saw (given the caller's footage)

    def __init_subclass__(cls, kind: str = "", reads: tuple[str, ...] = (), curved: bool = False,
                          filmed: bool = False, **kwargs):
        super().__init_subclass__(**kwargs)
        if kind:
            cls.reads, cls.curved, cls.filmed = reads, curved, filmed
            FIGURE_KINDS.register(kind, cls)

    @property
    def paper(self) -> bool:
        """Whether it draws the paper's values beside ours (the published values are handed to it)."""
        return False

    @property
    def linked(self) -> str | None:
        """A file it writes beside its image, for the page to link (none)."""
        return None

    def on_scene(self, scene: str) -> "FigureSpec":
        """The figure drawn on one scene's runs alone (a sequence's page): at every condition of those."""
        return replace(self, conditions=None)


def figure_spec(written: Mapping | FigureSpec, where: str = "") -> FigureSpec:
    """A figure spec as its kind declares it, checked (:meth:`~replication.specs.Spec.of`); ``where``: its file."""
    if isinstance(written, FigureSpec):
        return written
    name = written.get("name") if isinstance(written, Mapping) else None
    where = f"{where}: figure {name!r}" if where else f"figure {name!r}"
    made = kind_named(written, FIGURE_KINDS, written.get("kind") if isinstance(written, Mapping) else None, where,
                      "a figure")
    return made.of(written, f"{where} ({written['kind']})")


def figure_specs(experiment: Mapping, where: str = "") -> tuple[FigureSpec, ...]:
    """The experiment's report figures as typed specs (``where``: its file, said in an error)."""
    return tuple(figure_spec(written, where) for written in (experiment.get("report") or {}).get("figures") or ())


@dataclass(frozen=True, kw_only=True)
class MetricVsCondition(FigureSpec, kind="metric_vs_condition"):
    """``metric`` against the swept variable ``x`` (log axes as ``log_x``, ``log_y``; ``xlabel`` over the
    variable's words), a panel per value of ``by``, a fitted power law with ``fit_slope``; the paper's values of
    ``paper_table`` (``paper_metric``, at ``paper_x`` where a cell's condition gives no x, times
    ``paper_scale``); a diverged run cut at ``clip``."""

    metric: str
    x: str
    by: str | None = None
    log_x: bool = True
    log_y: bool = False
    xlabel: str = ""
    fit_slope: bool = False
    clip: float | None = None
    paper_table: str | list[str] | None = None
    paper_metric: str | None = None
    paper_x: dict[str, Any] = field(default_factory=dict)
    paper_scale: float = 1.0

    @property
    def paper(self) -> bool:
        return self.paper_table is not None


@dataclass(frozen=True, kw_only=True)
class MetricVsCost(FigureSpec, kind="metric_vs_cost"):
    """``metric`` against each of ``costs``, lines split by ``by``, ``log_y``; ``paired_to``: the metric
    minus that method's on the same data."""

    metric: str
    costs: tuple[str, ...] = ("evaluations_per_step", "ms_per_step")  # the work counted, and the time it took
    by: str | None = None
    log_y: bool = False
    paired_to: str | None = None


@dataclass(frozen=True, kw_only=True)
class RankingFigure(FigureSpec, kind="ranking"):
    """The rankings of mean ``metric`` over the values of ``over``, one per value of ``by``."""

    metric: str
    over: str = "scene"
    by: str | None = None


@dataclass(frozen=True, kw_only=True)
class PointSets(FigureSpec, kind="point_sets"):
    n: int = 400


@dataclass(frozen=True, kw_only=True)
class PerFrameCurve(FigureSpec, kind="per_frame_curve", reads=("per_frame",), curved=True):
    """The per-frame ``series`` over runs (``ylabel`` over its words), a diverged run cut at ``clip``."""

    series: str
    ylabel: str = ""
    clip: float | None = None


@dataclass(frozen=True, kw_only=True)
class Track(FigureSpec, kind="track", reads=("per_frame",), filmed=True):
    pass


@dataclass(frozen=True, kw_only=True)
class Snapshots(FigureSpec, kind="snapshots", reads=("per_frame",), filmed=True):
    """The ``frames`` (0-based; a list, or a list per scene), ``rows: frames`` for frames down."""

    frames: list[int] | dict[str, list[int]]
    rows: str = "methods"


@dataclass(frozen=True, kw_only=True)
class ModeStrip(FigureSpec, kind="mode_strip", reads=("strip", "per_frame"), filmed=True):
    window: tuple[int, int] | None = None  # the frames shaded (the hidden target's)


@dataclass(frozen=True, kw_only=True)
class OtbCurves(FigureSpec, kind="otb_curves", reads=("per_frame",), curved=True):
    pass


@dataclass(frozen=True, kw_only=True)
class AttributeMap(FigureSpec, kind="attribute_map", filmed=True):
    pass


@dataclass(frozen=True, kw_only=True)
class EncounterStrip(FigureSpec, kind="encounter_strip", reads=("per_frame",), filmed=True):
    distance: float = 20.0  # px: two targets this close are an encounter


@dataclass(frozen=True, kw_only=True)
class OutsideCurve(FigureSpec, kind="outside_curve", reads=("per_frame",), curved=True):
    pass


@dataclass(frozen=True, kw_only=True)
class TrackSnapshots(FigureSpec, kind="track_snapshots", reads=("tracks",), filmed=True):
    """The MOT ``frames`` (a list, or a list per scene key; none: ``columns`` frames evenly spaced), cropped
    to the boxes unless ``crop: false``."""

    frames: list[int] | dict[str, list[int]] | None = None
    columns: int = 4
    crop: bool = True


@dataclass(frozen=True, kw_only=True)
class IdentityTimeline(FigureSpec, kind="identity_timeline", reads=("tracks",), filmed=True):
    pass


@dataclass(frozen=True, kw_only=True)
class TrackVideo(FigureSpec, kind="track_video", reads=("tracks",), filmed=True):
    """A GIF of the first run of ``method`` on ``scene`` over the MOT ``frames`` [first, last], ``width`` px
    wide at ``fps``, written as ``link``."""

    method: str | None = None
    scene: str | None = None
    frames: tuple[int, int] | None = None
    width: int = 384
    fps: float | None = None
    link: str | None = None

    @property
    def linked(self) -> str | None:
        return self.link

    def on_scene(self, scene: str) -> "TrackVideo":
        return replace(self, conditions=None, scene=None if self.scene is None else scene)
