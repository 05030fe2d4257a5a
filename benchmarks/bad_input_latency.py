"""``python benchmarks/bad_input_latency.py [--repeats 3]``: the seconds a user waits for the one line of a bad
request, each in a fresh ``python -m replication`` as a user runs it (the fastest of ``--repeats``).

The test suite asserts what makes these quick (``tests/test_bad_input.py``: no numerical module imported
before a config error is said, no worker started before a data error is), never their seconds, which depend
on the machine's load; the seconds are this script's.  A config error takes the interpreter's start and
Hydra's composition; a data error (a damaged sequence) the numerical stack's imports too.
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GIRL = ROOT / "../shared/data/otb/Girl"
CONFIG_ERRORS = {  # what is wrong: the request
    "a value out of range": ["experiment=hspf_ungm", "experiment.model.Q=0"],
    "a word for a number": ["experiment=hspf_ungm", "base_seed=abc"],
    "an unknown key": ["experiment=hspf_ungm", "n_job=4"],
    "an unknown experiment": ["experiment=hspf_uncm"],
    "an unknown command": ["frobnicate"],
    "a path for a sequence": ["experiment=hspf", "sequences=[../otb/Girl]"],
    "a run count far beyond the paper's": ["experiment=hspf_ungm", "scale=quick", "experiment.runs.quick=1000000000"],
}


def data_errors(folder: Path) -> dict[str, list[str]]:
    """Requests on copies of Girl's first 20 frames, one damaged each (none without the OTB data)."""
    if not GIRL.is_dir():
        return {}
    found = {}
    for name, damage in (("a frame that is not an image", lambda g: (g / "img" / "0005.jpg").write_bytes(b"no")),
                         ("a missing frame", lambda g: (g / "img" / "0012.jpg").unlink())):
        girl = folder / name.replace(" ", "_") / "Girl"
        (girl / "img").mkdir(parents=True)
        for k in range(1, 21):
            shutil.copy(GIRL / "img" / f"{k:04d}.jpg", girl / "img")
        rows = (GIRL / "groundtruth_rect.txt").read_text().splitlines()[:20]
        (girl / "groundtruth_rect.txt").write_text("\n".join(rows) + "\n")
        damage(girl)
        found[name] = ["experiment=hspf", "scale=quick", f"data.otb={girl.parent}", "sequences=[Girl]"]
    return found


def seconds(args: list[str], out: Path, repeats: int) -> tuple[float, str]:
    """The fastest of ``repeats`` runs of the request, and the line it printed."""
    first = args[:1] if args and "=" not in args[0] else []  # a command goes first
    command = [sys.executable, "-m", "replication", *first, f"store={out / 'experiments'}",
               f"reports={out / 'reports'}", "outside_project=true", *args[len(first):]]
    best, said = float("inf"), ""
    for _ in range(repeats):
        started = time.perf_counter()
        done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, check=False)
        best = min(best, time.perf_counter() - started)
        said = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"(exit status {done.returncode})"
    return best, said


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs of each request; the fastest is shown")
    repeats = parser.parse_args().repeats
    with tempfile.TemporaryDirectory() as scratch:
        requests = {**CONFIG_ERRORS, **data_errors(Path(scratch))}
        width = max(map(len, requests))
        for what, args in requests.items():
            taken, said = seconds(args, Path(scratch), repeats)
            print(f"{what:<{width}}  {taken:5.2f} s  {said[:100]}", flush=True)


if __name__ == "__main__":
    main()
