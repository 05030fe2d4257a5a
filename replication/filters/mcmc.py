"""MCMC-PF: Metropolis-Hastings over the joint state with the MRF (Khan, Balch, Dellaert 2004).

As pinned in baselines.md §2.  Each frame:

1. start the chain from a random carried sample, every target moved by its motion;
2. run B + N iterations (B = ``burn_in`` x N): pick a target i uniformly, propose
   X'_i from the predictive mixture (a random carried sample r', then the motion
   model), accept with
   min(1, L(z_i | X'_i) prod_j psi(X'_i, X_j) / (L(z_i | X_i) prod_j psi(X_i, X_j))),
   the prior terms cancelling because the proposal is the predictive mixture;
   a model whose proposal fuses detections (:mod:`replication.models.boosted`) draws
   from q(x' | r') instead and L(z_i | X'_i) is multiplied by p(X'_i | r') / q(X'_i | r'),
   the chain then targeting the joint of (X'_i, r') (an auxiliary-variable MH);
3. keep the N states after burn-in (equal weights): the estimate is their mean;
   the ``carry`` (10 in bis_pf) best of them by likelihood times potentials
   (tracked incrementally; the predictive prior is not scored) go to the next frame
   (a carry of N or more: all of them, Khan et al.'s predictive mixture).

Carrying the 10 best is near-MAP: with the noise on the velocity (gps_qmcpf eq 14)
a ball's next velocity is then corrected by twice its position's correction
(x' = x + v + a/2, v' = v + a), a tracker on the edge of stability whose
velocity noise walks away, off the image on still balls (tests/test_bis.py);
carrying all samples, or the noise on the position, keeps it on them.

The proposals do not depend on the chain, so all of a frame's proposals and
their likelihoods are drawn in one vectorised pass per target; the chain itself
is a short scalar loop over the potentials of the moved target's neighbours.
psi is the bis_pf potential (eq 11), as for the other MRF methods.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from replication.filters.bis import _extents, _meeting
from replication.filters.frame import BoxTargets
from replication.filters.joint import JointFilter, JointState
from replication.filters.registry import drawn


@njit(cache=True)
def _log_psi(a, b, beta):
    """log psi for two boxes (cx, cy, w, h): bis_pf eq (11).  The overlap along x is
    (w_a + w_b) / 2 - |cx_a - cx_b|, capped by either width (one box inside the other)."""
    ox = min((a[2] + b[2]) / 2 - abs(a[0] - b[0]), a[2], b[2])
    oy = min((a[3] + b[3]) / 2 - abs(a[1] - b[1]), a[3], b[3])
    if ox <= 0 or oy <= 0:
        return 0.0
    ratio = (ox * oy) ** 2 / (a[2] * a[3] * b[2] * b[3])
    return -beta * ratio * ratio


@njit(cache=True)
def _chain(targets, proposals, log_like, initial, initial_like, log_uniforms, adjacent, beta):
    """Metropolis-Hastings accept decisions, and log(likelihoods x potentials) after each step.

    ``adjacent[i, j]`` marks the pairs whose boxes can overlap this frame (the
    MRF's edges); only they enter the potential.  Compiled: the chain is
    inherently sequential.
    """
    m, total = initial.shape[0], targets.shape[0]
    current, current_like = initial.copy(), initial_like.copy()
    pair = np.zeros((m, m))  # log psi of the current states
    for i in range(m):
        for j in range(m):
            if adjacent[i, j]:
                pair[i, j] = _log_psi(current[i], current[j], beta)
    total_like, current_psi = current_like.sum(), pair.sum() / 2
    accepted, score = np.zeros(total, dtype=np.bool_), np.empty(total)
    new_pair = np.zeros(m)
    for k in range(total):
        i = targets[k]
        delta_psi = 0.0
        for j in range(m):
            if adjacent[i, j]:
                new_pair[j] = _log_psi(proposals[k], current[j], beta)
                delta_psi += new_pair[j] - pair[i, j]
        if log_like[k] > -np.inf and (current_like[i] == -np.inf or log_like[k] - current_like[i] + delta_psi >= log_uniforms[k]):
            accepted[k] = True
            total_like += log_like[k] - current_like[i]
            current[i], current_like[i] = proposals[k], log_like[k]
            current_psi += delta_psi
            for j in range(m):
                if adjacent[i, j]:
                    pair[i, j] = pair[j, i] = new_pair[j]
        score[k] = total_like + current_psi
    return accepted, score


@njit(cache=True)
def _held(accepted, targets, m):
    """held[k, i]: the row of target i's state after chain step k, its last accepted proposal k' <= k (row
    k'), or its initial state (row total + i) if none yet."""
    total = targets.size
    held = np.empty((total, m), np.intp)
    last = total + np.arange(m)
    for k in range(total):
        if accepted[k]:
            last[targets[k]] = k
        held[k] = last
    return held


@drawn("orange", "-", "v")
@dataclass
class MCMCPF(JointFilter):
    n_particles: int = 6000  # samples kept per frame after burn-in
    burn_in: float = 0.25  # share of N discarded first
    carry: int = 10  # best samples carried to the next frame
    beta: float = 4.0

    def __post_init__(self):
        if self.n_particles <= 0 or not 0 <= self.burn_in < 10 or self.carry <= 0 or self.beta < 0:
            raise ValueError(f"need N > 0, 0 <= burn_in, carry > 0, beta >= 0; got {self}")

    def start(self, models: list, rng: np.random.Generator) -> JointState:
        state = super().start(models, rng)
        state.carried = [p[: self.carry] for p in state.particles]  # the joint samples the next frame starts from
        return state

    def add(self, state: JointState, model) -> None:
        super().add(state, model)
        state.carried.append(state.particles[-1][: self.carry])

    def remove(self, state: JointState, index: int) -> None:
        super().remove(state, index)
        del state.carried[index]

    def step(self, state: JointState, z) -> None:
        rng, m = state.rng, len(state.models)
        state.t += 1
        burn = int(self.burn_in * self.n_particles)
        total = burn + self.n_particles
        targets = rng.integers(m, size=total)
        sources = rng.integers(len(state.carried[0]), size=total)
        boxes = state.box_targets()
        proposals, log_like, initial, initial_like, adjacent = (
            self.propose(state, z, targets, sources) if boxes is None else self.propose_boxes(state, z, targets, sources, boxes))
        accepted, score = _chain(targets, proposals, log_like, initial, initial_like, np.log(rng.random(total)), adjacent, self.beta)
        held = _held(accepted, targets, m)
        rows = np.concatenate([proposals, initial])
        kept = rows[held[burn:].T]  # (M, N, d): each target's samples contiguous
        # ties are rejected steps, whose joint states are the same; a stable sort orders them by step on
        # every CPU (numpy's default sort is chosen by the CPU's vector extensions)
        best = np.argsort(score[burn:], kind="stable")[-self.carry :]
        weights = np.full(self.n_particles, 1.0 / self.n_particles)
        with np.errstate(divide="ignore"):
            log_weights = np.log(weights)
        for i in range(m):
            state.record(i, kept[i], weights, False, log_weights)
        state.carried = [kept[i, best] for i in range(m)]

    def propose(self, state: JointState, z, targets: np.ndarray, sources: np.ndarray) -> tuple:
        """Every proposal of the chain, one pass per target (X'_i from carried sample r' by its model), the
        chain's start (carried sample ``start`` moved by every motion), their log-likelihoods (with the
        proposal's log p / q) and the MRF's edges among the targets' reachable states."""
        rng, m, carried = state.rng, len(state.models), state.carried
        total = len(targets)
        proposals = np.empty((total, carried[0].shape[1]))
        log_like = np.empty(total)
        chosen = [np.flatnonzero(targets == i) for i in range(m)]
        log_correction = np.zeros(total)  # log p / q of a proposal: 0 for the predictive mixture itself
        for i, model in enumerate(state.models):  # every proposal, one pass per target
            proposals[chosen[i]], log_correction[chosen[i]] = model.propose(carried[i][sources[chosen[i]]], state.t, rng)
        start = int(rng.integers(len(carried[0])))
        initial = np.stack([model.propagate(p[start : start + 1], state.t, rng)[0] for model, p in zip(state.models, carried)])
        reachable = [np.vstack([proposals[chosen[i]], initial[i]]) for i in range(m)]
        initial_like = np.empty(m)
        for i, model in enumerate(state.models):  # the likelihoods of a target's proposals and start, one call
            scored = model.log_likelihood(reachable[i], z, state.t)
            log_like[chosen[i]], initial_like[i] = scored[:-1] + log_correction[chosen[i]], scored[-1]
        return proposals, log_like, initial, initial_like, _adjacent(np.concatenate(reachable), np.cumsum([len(r) for r in reachable]))

    def propose_boxes(self, state: JointState, z, targets: np.ndarray, sources: np.ndarray, boxes: BoxTargets) -> tuple:
        """:meth:`propose` for box targets (:class:`~replication.filters.frame.BoxTargets`): every target's
        proposals moved in one call, then every start, then all their likelihoods in one call, with the
        same draws in the same order and the same numbers (a box model's log p / q is 0)."""
        rng, m = state.rng, len(state.models)
        order = np.argsort(targets, kind="stable")  # target after target, each in chain order: flatnonzero's
        offsets = np.concatenate([[0], np.cumsum(np.bincount(targets, minlength=m))])
        carried = np.stack(state.carried)
        moved = boxes.propagate(carried[targets[order], sources[order]], offsets, state.t, rng)
        start = int(rng.integers(carried.shape[1]))
        initial = boxes.propagate(carried[:, start], np.arange(m + 1), state.t, rng)
        reachable, ends = _with_starts(moved, offsets, initial)
        scored = boxes.log_likelihood(reachable, np.concatenate([[0], ends]), z, state.t)
        proposals, log_like = np.empty_like(moved), np.empty(len(targets))
        proposals[order] = moved
        log_like[order] = np.delete(scored, ends - 1) + 0.0
        return proposals, log_like, initial, scored[ends - 1], _adjacent(reachable, ends)


def _adjacent(reachable: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """adjacent[i, j]: whether targets i and j can overlap (their reachable states' clouds meet: the MRF's
    edges), from the targets' rows stacked (target i's end before ``ends[i]``)."""
    m = len(ends)
    adjacent = np.zeros((m, m), dtype=bool)
    for i, j in _meeting(*_extents(reachable, ends)):
        adjacent[i, j] = adjacent[j, i] = True
    return adjacent


@njit(cache=True)
def _with_starts(moved, offsets, initial):
    """Each target's proposals (``moved`` rows ``offsets[i]:offsets[i + 1]``) followed by its start, stacked,
    and where each target's rows end."""
    m = initial.shape[0]
    out = np.empty((moved.shape[0] + m, moved.shape[1]))
    ends = np.empty(m, np.int64)
    for i in range(m):
        first = offsets[i] + i
        out[first : first + offsets[i + 1] - offsets[i]] = moved[offsets[i] : offsets[i + 1]]
        ends[i] = offsets[i + 1] + i + 1
        out[ends[i] - 1] = initial[i]
    return out, ends
