"""``python -m replication.scenes experiment=<name> [scale=paper|quick] [scene=<key>] [out=DIR] [format=mp4|images]
[boxes=true]``.

Writes the synthetic scenes of an experiment (its ``scenes:`` block; real
sequences are already on disk) at the scale asked for (the config's by
default, as for every command), so a person can watch them.
"""

import sys
from dataclasses import dataclass
from pathlib import Path

from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from replication.arguments import read
from replication.errors import fail
from replication.paths import CONF_DIR, experiment_names, resolve
from replication.scales import SCALES, at_scale
from replication.scenes.export import write_sequence
from replication.scenes.factory import build_sequence, scene_kind

@dataclass(frozen=True)
class Options:
    experiment: str | None = None
    scale: str | None = None
    scene: str | None = None  # one scene's key (every synthetic scene by default)
    out: str | None = None
    format: str = "mp4"
    boxes: bool = False


def main(argv: list[str]) -> None:
    options, _ = read(argv, Options, "scenes")
    name = options.experiment
    if name not in experiment_names():
        fail(f"name an experiment with scenes: experiment=<name>; known: {', '.join(experiment_names())}")
    out = Path(options.out or resolve("reports") / "scenes")
    video = options.format == "mp4"
    boxes = options.boxes
    scale = options.scale
    if scale is not None and scale not in SCALES:
        fail(f"scale must be one of {', '.join(SCALES)}, got {scale!r}")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"experiment={name}"] + ([f"scale={scale}"] if scale else []))
    scenes = OmegaConf.to_container(cfg.experiment.scenes, resolve=True) if "scenes" in cfg.experiment else {}
    scenes = at_scale(scenes, cfg.scale)  # a scene's frames may differ by scale ({paper: 1000, quick: 100})
    chosen = options.scene
    synthetic = {k: v for k, v in scenes.items() if not scene_kind(v).real and chosen in (None, k)}
    if not synthetic:
        fail(f"experiment {name!r} has no synthetic scene{' ' + repr(chosen) if chosen else ''}")
    for spec in synthetic.values():
        print(write_sequence(build_sequence(spec), out, video=video, boxes=boxes))


if __name__ == "__main__":
    main(sys.argv[1:])
