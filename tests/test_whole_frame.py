"""The whole-frame steps (issue 59): every joint filter, and independent bootstrap filters, stepped for all
targets at once give the per-target step's numbers to the bit (the same draws in the same order), on a
synthetic scene of balls; and their compiled parts give numpy's bits (sums, BLAS products, transcendentals)."""

import numpy as np
import pytest
from conftest import libm_exp, libm_log

from replication import BISPF, bootstrap
from replication.compiled import matvec
from replication.filters import frame
from replication.filters.bis import MIPF, cloud_extents, neighbours
from replication.filters.dmot import DMOT
from replication.filters.mcmc import MCMCPF
from replication.filters.mean_field import MFMC
from replication.filters.tracker import tracker
from replication.models.box import BoxModel
from replication.scenes import SyntheticScene
from replication.smc.loop import Summaries
from replication.smc.weights import DegenerateWeightsError, normalise
from replication.smc.work import Counted, Work
from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram
from replication.vision.joint import ColourLikelihoods


def balls(n_targets=5, frames=8, seed=3):
    """A noisy scene of 20 x 20 balls moving about, close enough that their clouds meet."""
    rng = np.random.default_rng(seed)
    starts = rng.uniform(30, 90, (n_targets, 2))
    scene = SyntheticScene({
        "size": [120, 120], "frames": frames, "seed": seed, "camera_noise": 2.0,
        "background": {"kind": "noise", "colour": [60, 120, 60], "amplitude": 12},
        "targets": [{"shape": "ball", "size": [20, 20], "colour": [40, 220, 200],
                     "motion": {"kind": "scripted", "keyframes": [[0, *s], [frames - 1, *(s + rng.uniform(-8, 8, 2))]]}}
                    for s in starts]})
    return scene, [np.array([x, y, 20.0, 20.0]) for x, y in starts]


def models(scene, boxes, work, kind="constant_velocity", cache=None):
    cache, first = {} if cache is None else cache, scene.frame(0)
    return {k: Counted(BoxModel(box, ColourLikelihood.from_frame(first, box, ColourHistogram((8, 8, 4), grid=(10, 10)), 0.1),
                                kind=kind, size="fixed", accel_sd=0.63, initial_sd=(1.0, 1.0, 0.1, 0.1), cache=cache), work)
            for k, box in enumerate(boxes)}


def tracked(build, whole: bool, monkeypatch, kind="constant_velocity"):
    """Outputs and work of a tracker over the scene, with or without the whole-frame steps."""
    with monkeypatch.context() as patch:
        if not whole:
            patch.setattr(frame.BoxTargets, "of", classmethod(lambda cls, models: None))
        scene, boxes = balls()
        work = Work()
        method = tracker(build)
        method.start(models(scene, boxes, work, kind), lambda name: np.random.default_rng(len(name) * 7 + ord(name[-1])))
        for _ in method.track(scene.frame(k) for k in range(1, scene.n_frames)):
            pass
        return method.outputs(), work


@pytest.mark.parametrize("build", [
    lambda: BISPF(n_particles=60, n_joint=300),
    lambda: MFMC(n_particles=60, iterations=3),
    lambda: DMOT(n_particles=60, iterations=3),
    lambda: MIPF(n_particles=60),
    lambda: MCMCPF(n_particles=300, carry=10),
    lambda: bootstrap(60, "multinomial", 1.0),
    lambda: bootstrap(60, "multinomial", 0.5),
], ids=["BIS-PF", "MFMC", "DMOT", "MIPF", "MCMC", "bootstrap", "bootstrap-ess"])
def test_the_whole_frame_step_is_the_per_target_step_to_the_bit(build, monkeypatch):
    whole, whole_work = tracked(build, True, monkeypatch)
    alone, alone_work = tracked(build, False, monkeypatch)
    for a, b in zip(whole, alone):
        for name in ("means", "variances", "ess", "resampled", "degenerate"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
        assert a.log_evidence == b.log_evidence or np.isnan(a.log_evidence) and np.isnan(b.log_evidence)
    assert (whole_work.evaluations, whole_work.propagations) == (alone_work.evaluations, alone_work.propagations)


def test_box_targets_take_only_plain_box_models_of_one_motion_and_pattern():
    scene, boxes = balls(3)
    work = Work()
    plain = list(models(scene, boxes, work).values())
    assert frame.BoxTargets.of(plain) is not None
    walk = list(models(scene, boxes, work, "random_walk", plain[0].cache).values())
    assert frame.BoxTargets.of(plain[:2] + walk[2:]) is None
    other_cache = list(models(scene, boxes, work).values())  # its own frame cache
    assert frame.BoxTargets.of(plain[:2] + other_cache[2:]) is None
    wide = ColourLikelihood.from_frame(scene.frame(0), boxes[0], ColourHistogram((8, 8, 4), grid=(12, 10)), 0.1)
    assert ColourLikelihoods.of([plain[0].likelihood, wide]) is None


def test_every_targets_likelihood_in_one_call_is_each_ones_own():
    scene, boxes = balls(4)
    likelihoods = [m.likelihood for m in models(scene, boxes, Work()).values()]
    likelihoods[2].sigma = 0.25
    rng = np.random.default_rng(0)
    rows = [np.column_stack([rng.normal(b[:2], 6, (n, 2)), np.full((n, 2), 20.0)]) for b, n in zip(boxes, (30, 0, 7, 50))]
    rows[3][:5, 0] = -40.0  # outside the image: -inf
    bin_image = likelihoods[0].prepare(scene.frame(2))
    joint = ColourLikelihoods.of(likelihoods).log_likelihood(np.concatenate(rows), np.cumsum([0, 30, 0, 7, 50]), bin_image)
    own = np.concatenate([like.log_likelihood(r, bin_image) for like, r in zip(likelihoods, rows)])
    assert own.tobytes() == joint.tobytes() and np.isneginf(joint[-50:-45]).all()


def test_normalised_rows_are_normalise_to_the_bit_and_fail_as_it_does():
    rng = np.random.default_rng(1)
    for n in (1, 7, 8, 130, 400, 1000):
        predicted = np.log(rng.dirichlet(np.ones(n), 3))
        likelihood = rng.normal(-50, 30, (3, n))
        likelihood[1] = -np.inf  # no particle explains the frame: the predicted weights, flagged
        weights, log_totals, degenerate = frame.normalise_rows(predicted, likelihood, corrected=False)
        for i, lw in enumerate((predicted[0] + likelihood[0], predicted[1], predicted[2] + likelihood[2])):
            expected, log_total = normalise(lw)
            assert weights[i].tobytes() == expected.tobytes() and log_totals[i] == log_total
        assert degenerate.tolist() == [False, True, False]
    with pytest.raises(frame.NotFinite):
        frame.normalise_rows(np.zeros((1, 3)), np.array([[0.0, np.nan, 0.0]]), corrected=True)
    with pytest.raises(DegenerateWeightsError):
        frame.normalise_rows(np.full((1, 3), -np.inf), np.zeros((1, 3)), corrected=True)


@pytest.mark.parametrize("rows", [1, 2, 3, 9, 64, 65, 333])
@pytest.mark.parametrize("columns", [1, 2, 9, 65, 200])
def test_the_compiled_matrix_vector_product_is_numpys(rows, columns):
    """numpy's ``@`` calls BLAS's dot product for a one-row matrix, its gemv otherwise; so does matvec."""
    rng = np.random.default_rng(rows * 1000 + columns)
    block = rng.normal(size=(rows, columns))
    x, y = rng.normal(size=columns), rng.normal(size=rows)
    assert matvec(block, x).tobytes() == (block @ x).tobytes()
    assert matvec(block.T, y).tobytes() == (block.T @ y).tobytes()


def test_mean_field_and_dmot_interactions_are_their_numpy_forms_to_the_bit():
    from replication.filters.bis import log_potential_table, reaching

    rng = np.random.default_rng(7)
    for trial in range(40):
        m, n = int(rng.integers(2, 7)), int(rng.integers(1, 80))
        clouds = [np.column_stack([rng.normal(c, rng.uniform(1, 12), (n, 2)), np.full((n, 2), 14.0), rng.normal(size=(n, 2))])
                  for c in rng.uniform(0, 60, (m, 2))]
        pi = [w / w.sum() for w in rng.random((m, n)) ** 3]
        low, high = cloud_extents(clouds)
        blocks = {(i, j): (reaching(clouds[i], low[j], high[j]), reaching(clouds[j], low[i], high[i])) for i, j in neighbours(clouds)}
        q = list(pi)
        for _ in range(3):  # MFMC's iterations in numpy
            field = [np.zeros(n) for _ in pi]
            for (i, j), (r, c) in blocks.items():
                table = log_potential_table(clouds[i][r], clouds[j][c], 4.0)
                field[i][r] += table @ q[j][c]
                field[j][c] += table.T @ q[i][r]
            q = [normalise(libm_log(p) + f)[0] for p, f in zip(pi, field)]
        found = MFMC(n_particles=n, iterations=3, beta=4.0).interact(clouds, pi, None)
        assert all(a.tobytes() == b.tobytes() for a, b in zip(found, q))
        dmot = DMOT(sigma_angle=0.4, sigma_speed=1.5, alpha2=1.5)
        means = [np.array([30.0, 30, 14, 14, 0, 0]), np.array([31.0, 29, 14, 14, 0, 0])]
        motion = clouds[0][:, :2] - means[-1][:2]
        reference = means[-1][:2] - means[-2][:2]
        norms = np.linalg.norm(motion, axis=1) * np.linalg.norm(reference)
        theta = np.arccos(np.clip(np.divide(motion @ reference, norms, out=np.ones(n), where=norms > 0), -1.0, 1.0))
        speed = np.linalg.norm(motion, axis=1) - np.linalg.norm(reference)
        inertia = 1.0 + libm_exp(-(theta**2) / 0.4**2) * libm_exp(-(speed**2) / 1.5**2) / 1.5
        assert dmot.inertia(clouds[0], means).tobytes() == inertia.tobytes()
        assert (dmot.inertia(clouds[0], means[:1]) == 1.0).all()


def test_the_clouds_extents_are_reduceats_and_nan_spreads():
    rng = np.random.default_rng(2)
    for trial in range(200):
        clouds = [np.column_stack([rng.uniform(0, 100, (k, 2)), rng.uniform(0, 20, (k, 2))]) for k in rng.integers(1, 30, 5)]
        if trial % 4 == 0:
            clouds[1][0, 2] = np.nan
        stacked, starts = np.concatenate(clouds), np.cumsum([0] + [len(c) for c in clouds[:-1]])
        half = stacked[:, 2:4] / 2
        low, high = cloud_extents(clouds)
        np.testing.assert_array_equal(low, np.minimum.reduceat(stacked[:, :2] - half, starts))
        np.testing.assert_array_equal(high, np.maximum.reduceat(stacked[:, :2] + half, starts))
        meet = ((low[:, None] < high[None, :]) & (low[None, :] < high[:, None])).all(axis=-1)
        assert neighbours(clouds) == [(int(i), int(j)) for i, j in zip(*np.nonzero(np.triu(meet, 1)))]


def test_many_targets_move_as_each_alone():
    """BoxModel.moved over stacked targets: each target's rows and normals as its own propagate's."""
    for kind, size in (("constant_velocity", "fixed"), ("random_walk", "drifting")):
        model = BoxModel(np.array([50.0, 40, 20, 20]), None, kind=kind, size=size, min_size=19.9)
        clouds = [model.sample_initial(n, np.random.default_rng(n)) for n in (5, 0, 40)]
        alone = [model.propagate(c, 1, np.random.default_rng(9)) for c in clouds]  # each from the same stream
        per_row = model._sources.blocks * model._sources.width
        draws = np.concatenate([np.random.default_rng(9).standard_normal(per_row * len(c)) for c in clouds])
        together = model.moved(np.concatenate(clouds), draws, np.cumsum([0, 5, 0, 40]))
        assert together.tobytes() == np.concatenate(alone).tobytes()


def test_summaries_of_a_whole_frame_step_are_recorded_per_target():
    """A target born later gets the frame step's records from then on, as the per-target step gives them."""
    scene, boxes = balls(3)
    work = Work()
    boxed = list(models(scene, boxes, work).values())
    bis = BISPF(n_particles=40, n_joint=100)
    state = bis.start(boxed[:2], np.random.default_rng(0))
    bis.step(state, scene.frame(1))
    bis.add(state, boxed[2])
    bis.step(state, scene.frame(2))
    assert [len(r.means) for r in state.records] == [2, 2, 1] and isinstance(state.records[0], Summaries)
