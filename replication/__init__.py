"""Reproducible replication of five particle-filter papers on visual tracking, and the filters as a library.

Everything a user needs to run the filters on their own model or video is a
top-level name, ``from replication import bootstrap, kalman_filter, VideoSequence``:

* the SMC core (:mod:`replication.smc`): :class:`ParticleFilter`, the one
  propose -> move -> weight -> estimate -> resample loop, which takes any
  :class:`StateSpaceModel` (``sample_initial``, ``propagate``, ``log_likelihood``);
  its :class:`ResamplingPolicy` and the resampling schemes; ESS and weight helpers;
* the filters (:mod:`replication.filters`): :func:`bootstrap` and the five papers'
  variants, every registered builder by name (:func:`builders`, the entry points of
  ``replication.filters``, a user's own included), :func:`builder` for one name or
  import path, :func:`build_filter` to make one from config keys, :func:`drawn` to
  declare how a builder's methods look on figures, and :func:`tracker` to step one or
  many targets through frames;
* models (:mod:`replication.models`): :class:`LinearGaussian` with its exact
  :func:`kalman_filter`, :class:`UNGM`, :class:`AdditiveGaussianModel` to derive
  your own scalar model from, :class:`BoxModel` for a target's box in video, and the one
  conversion of a box between its corner (x, y, w, h) and centre (cx, cy, w, h) forms
  (:func:`centre_boxes`, :func:`corner_boxes`, :func:`centres`);
* observation models (:mod:`replication.vision`): :class:`ColourHistogram`,
  :class:`ColourLikelihood`, :class:`FusionLikelihood`, the Bhattacharyya coefficient;
* metrics (:mod:`replication.metrics`): OTB precision and success, CLEAR MOT,
  IDF1, HOTA, RMSE and filter diagnostics;
* sequences (:mod:`replication.scenes`): :class:`VideoSequence` (any video file),
  :class:`OTBSequence`, :func:`load_mot`, :class:`SyntheticScene`;
* :func:`load_runs`, :func:`load_frames`: an experiment's stored runs (and their frames) as tidy tables.

Each name is imported from its module on first use (PEP 562), so ``import replication``
itself loads neither numpy nor OpenCV and the command line answers at once.  The
tutorials are ``docs/tutorial_state_space.md`` and ``docs/tutorial_video.md``.
"""

import functools

__version__ = "0.1.0"

_EXPORTS = {  # module: the public names it defines, in the order of the API reference
    "replication.smc.loop": (
        "ParticleFilter", "StateSpaceModel", "ResamplingPolicy", "FilterOutput", "Proposal", "Move",
    ),
    "replication.smc.resampling": ("RESAMPLERS", "multinomial", "residual", "stratified", "systematic"),
    "replication.smc.weights": ("ess", "normalise", "weighted_mean", "weighted_variance"),
    "replication.filters.registry": ("build_filter", "builder", "builders", "drawn"),  # then every builder
    "replication.filters.tracker": ("tracker", "Tracker"),
    "replication.models": ("MODELS",),
    "replication.models.additive": ("AdditiveGaussianModel",),
    "replication.models.linear_gaussian": ("LinearGaussian", "kalman_filter"),
    "replication.models.ungm": ("UNGM",),
    "replication.models.point_mass": ("point_mass_filter",),
    "replication.models.box": ("BoxModel",),
    "replication.boxes": ("centres", "centre_boxes", "corner_boxes"),
    "replication.models.boosted": ("BoostedBoxModel",),
    "replication.vision.histogram": ("ColourHistogram", "hsv_bin_image"),
    "replication.vision.colour": ("ColourLikelihood",),
    "replication.vision.fusion": ("FusionLikelihood",),
    "replication.vision.likelihood": (
        "bhattacharyya", "bhattacharyya_distance", "gaussian_similarity_log_likelihood",
    ),
    "replication.vision.ssim": ("structural_similarity",),
    "replication.metrics.scalar": ("rmse", "filter_diagnostics"),
    "replication.metrics.tracking": (
        "centre_error", "iou", "precision_curve", "precision_at", "success_curve", "success_auc",
    ),
    "replication.metrics.multi": ("clear_mot", "idf1"),
    "replication.metrics.mot": ("mot_metrics",),
    "replication.metrics.hota": ("hota",),
    "replication.scenes.base": ("Sequence",),
    "replication.scenes.video": ("VideoSequence",),
    "replication.scenes.otb": ("OTBSequence", "find_otb"),
    "replication.scenes.mot": ("MotSequence", "load_mot"),
    "replication.scenes.synthetic": ("SyntheticScene",),
    "replication.scenes.export": ("write_sequence",),
    "replication.errors": ("ConfigError",),
    "replication.runner.results": ("load_runs", "load_frames"),
}


@functools.cache
def _module_of() -> dict[str, str]:
    """Each public name's module: :data:`_EXPORTS`, and after the filters' registry every builder this
    package registers (its entry points, :data:`~replication.filters.registry.FILTERS`), so a new filter
    is a public name by its registration alone.  Read at the first use, not at import."""
    from replication.errors import ConfigError
    from replication.filters.registry import FILTERS

    try:
        builders = {point.attr: point.module for point in FILTERS.values()
                    if point.module.startswith(f"{__name__}.")}
    except ConfigError:  # not installed: no builder is registered (naming one in a config says so)
        builders = {}
    found = {}
    for module, names in _EXPORTS.items():
        found.update(dict.fromkeys(names, module))
        if module == "replication.filters.registry":
            found.update(builders)
    return found


def __getattr__(name: str):
    """``__all__`` and each public name, its module imported on first use and the name kept here (PEP 562)."""
    from importlib import import_module

    if name == "__all__":
        return ["__version__", *_module_of()]
    if name not in _module_of():
        raise AttributeError(f"module 'replication' has no attribute {name!r}")
    value = getattr(import_module(_module_of()[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), "__all__", "__version__", *_module_of()})
