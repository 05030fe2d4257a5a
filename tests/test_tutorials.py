"""The tutorials in docs/ run as written, print the numbers they quote, and their claims hold.

A tutorial is a Markdown file whose ```python blocks run in order in one namespace,
as one script; a ```text block right after a python block is what that block prints.
Quoted numbers are compared to within one unit of their last digit (rounding on another
platform, or a video decoder of another OpenCV build, may move it).
"""

import contextlib
import io
import re

import numpy as np
import pytest
from conftest import PROJECT_ROOT

import replication as rp
from replication.paths import resolve
from replication.scenes.otb import OTB_ROOT

BLOCK = re.compile(r"```(python|text)\n(.*?)```", re.DOTALL)
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
HAVE_GIRL = (resolve(OTB_ROOT) / "Girl").is_dir()


def run_tutorial(name: str) -> dict:
    """Run ``docs/<name>``'s python blocks; check each quoted output; return the namespace."""
    path = PROJECT_ROOT / "docs" / name
    namespace: dict = {"__name__": "__tutorial__"}
    printed = None
    for kind, text in BLOCK.findall(path.read_text()):
        if kind == "python":
            with contextlib.redirect_stdout(io.StringIO()) as out:
                exec(compile(text, str(path), "exec"), namespace)  # noqa: S102 (the tutorial's own code)
            printed = out.getvalue()
            continue
        assert printed is not None, f"{name}: a text block that follows no python block:\n{text}"
        assert NUMBER.sub("#", printed) == NUMBER.sub("#", text), f"{name} printed\n{printed}\nnot\n{text}"
        for quoted, number in zip(NUMBER.findall(text), NUMBER.findall(printed)):
            last_digit = 10.0 ** -len(quoted.partition(".")[2])
            assert abs(float(number) - float(quoted)) <= last_digit, f"{name} printed\n{printed}\nnot\n{text}"
        printed = None
    return namespace


def test_state_space_tutorial_agrees_with_the_exact_filters():
    tutorial = run_tutorial("tutorial_state_space.md")
    # section 1: the bootstrap filter on the user's linear Gaussian model against the Kalman filter
    gap, runs, log_likelihood = tutorial["gap_kalman"], tutorial["runs"], tutorial["log_likelihood"]
    assert gap.max() < 0.5 and gap.mean() < 0.1  # in posterior standard deviations
    for estimates in runs.values():  # p-hat is unbiased: E log p-hat = log p - var / 2 to first order
        standard_error = estimates.std() / np.sqrt(len(estimates))
        assert abs(estimates.mean() - log_likelihood + estimates.var() / 2) < 3 * standard_error
    assert 2.0 < runs[100].std() / runs[1000].std() < 5.0  # sqrt(10) = 3.2
    # section 2: stochastic volatility against the grid filter, itself converged in its spacing and width
    volatility, y, grid_means = tutorial["volatility"], tutorial["y"], tutorial["grid_means"]
    assert tutorial["gap_grid"].max() < 0.5 and tutorial["gap_grid"].mean() < 0.1
    for n_points, half_width in ((801, 6.0), (534, 8.0)):
        refined = rp.point_mass_filter(volatility, y, n_points=n_points, half_width=half_width)[0]
        assert np.abs(refined - grid_means).max() < 1e-9
    assert abs(volatility.mu) + 5 * np.sqrt(volatility.P0) < 6.0
    assert 10 * 12.0 / 400 < np.sqrt(tutorial["grid_variances"]).min()


@pytest.mark.skipif(not HAVE_GIRL, reason="../shared/data/otb is not beside the project")
def test_video_tutorial_tracks_better_than_a_box_left_still(tmp_path, monkeypatch):
    monkeypatch.setenv("REPLICATION_HOME", str(PROJECT_ROOT))  # relative data paths: from the checkout
    monkeypatch.chdir(tmp_path)  # where the tutorial writes its video and figure
    tutorial = run_tutorial("tutorial_video.md")
    scores = tutorial["scores"]
    still_precision, still_success, _ = scores.pop("box left still")
    assert len(scores) == 5
    for precision, success, far in scores.values():  # every run beats the baseline, and loses her at the end
        assert precision > still_precision and success > still_success
        assert far[0] > 90 and far[-1] == tutorial["video"].n_frames - 1
    assert (tmp_path / "tutorial_video" / "scores.png").stat().st_size > 0
