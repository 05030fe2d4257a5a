"""Multi-target metrics: mean error per target (bis_pf) and its identity-free and while-tracked
readings, OSPA, close encounters, track loss, CLEAR MOT and IDF1.

Ground truth and hypotheses are centre tracks: ``truth`` (T, M, 2) with a
presence mask (T, M), ``estimates`` (T, K, 2) with a presence mask (T, K).
A truth-hypothesis pair can match in a frame when their distance is below
``threshold`` px.

CLEAR MOT (Bernardin and Stiefelhagen 2008), as py-motmetrics computes it:
each frame first keeps last frame's pairs that are still within the threshold,
then assigns the rest by minimum total distance (Hungarian); a truth matched to
a hypothesis other than the one it was last matched to is an identity switch.
MOTA = 1 - (misses + false positives + switches) / truth detections;
MOTP = mean distance over matches.  IDF1 (Ristani et al. 2016): one global
one-to-one assignment of truth tracks to hypothesis tracks maximising the frames
they match (IDTP); IDF1 = 2 IDTP / (truth detections + hypothesis detections).
"""

import numpy as np
from scipy.optimize import linear_sum_assignment

from replication.metrics.means import fsum_mean

UNMATCHABLE = 1e9


def mean_error_per_target(estimates: np.ndarray, truth: np.ndarray) -> float:
    """bis_pf's error: mean over frames and targets of |estimate_m - truth_m| (px), estimate m for target m."""
    return fsum_mean(np.linalg.norm(np.asarray(estimates) - np.asarray(truth), axis=-1))


def identity_free_error(estimates: np.ndarray, truth: np.ndarray) -> float:
    """The error with identities left out: in each frame, the estimates assigned to the truths by minimum
    total distance (Hungarian, :func:`scipy.optimize.linear_sum_assignment`), the mean matched distance
    over frames and targets.  Two estimates that swap balls keep a small error here."""
    return fsum_mean(assignments(estimates, truth)[1])


def ospa(estimates: np.ndarray, truth: np.ndarray, cutoff: float, order: int = 1) -> float:
    """Mean over frames of the OSPA distance (Schuhmacher, Vo and Vo 2008) between equally many estimates
    and truths: (min over assignments of the mean of min(d, ``cutoff``)^p)^(1/p)."""
    d = np.minimum(_pairwise(estimates, truth), cutoff) ** order
    return fsum_mean([fsum_mean(d[k][linear_sum_assignment(d[k])]) ** (1 / order) for k in range(len(d))])


def _pairwise(estimates: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """(T, M, M): distance from estimate i to truth j in each frame."""
    return np.linalg.norm(np.asarray(estimates)[:, :, None, :] - np.asarray(truth)[:, None, :, :], axis=-1)


def close_encounters(truth: np.ndarray, distance: float) -> int:
    """How many times two truths come within ``distance`` of each other (a pair's run of close frames counts
    once): the occasions for an identity swap."""
    d = _pairwise(truth, truth)
    close = (d < distance) & ~np.eye(d.shape[1], dtype=bool)
    starts = close[1:] & ~close[:-1]
    return int(np.triu(starts, k=1).sum() + np.triu(close[0], k=1).sum())


def persistent_onsets(flags: np.ndarray, patience: int) -> np.ndarray:
    """(M,) per target (column of ``flags``, frames x targets), the first frame of its first run of ``patience``
    True frames in a row, or the number of frames where there is none."""
    flags = np.asarray(flags, dtype=bool)
    run = np.zeros(flags.shape[1], dtype=int)
    onset = np.full(flags.shape[1], len(flags))
    for k, row in enumerate(flags):
        run = np.where(row, run + 1, 0)
        onset = np.where((run >= patience) & (onset == len(flags)), k - patience + 1, onset)
    return onset


def loss_onsets(estimates: np.ndarray, truth: np.ndarray, threshold: float, patience: int) -> np.ndarray:
    """(M,) the frame at which each target's first loss begins (the first of ``patience`` frames in a row
    over ``threshold`` px from it), or the number of frames for a target never lost."""
    return persistent_onsets(np.linalg.norm(np.asarray(estimates) - np.asarray(truth), axis=-1) > threshold, patience)


def assignments(estimates: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(frames, M) the target each estimate is given by the frame's optimal assignment (Hungarian over centre
    distances), and its distance to that target."""
    distances = _pairwise(estimates, truth)
    assigned = np.zeros(distances.shape[:2], dtype=int)
    for k, frame in enumerate(distances):
        rows, columns = linear_sum_assignment(frame)
        assigned[k, rows] = columns
    return assigned, np.take_along_axis(distances, assigned[..., None], axis=-1)[..., 0]


def swapped(estimates: np.ndarray, truth: np.ndarray, threshold: float) -> np.ndarray:
    """(frames, M) bool: estimate m sits on another target, the one the frame's optimal assignment gives it,
    within ``threshold`` px: an identity swap, not a loss of lock."""
    assigned, distance = assignments(estimates, truth)
    return (assigned != np.arange(assigned.shape[1])) & (distance <= threshold)


def off_every_target(estimates: np.ndarray, truth: np.ndarray, threshold: float) -> np.ndarray:
    """(frames, M) bool: estimate m lies over ``threshold`` px from every target: lock lost, whoever it was on."""
    return _pairwise(estimates, truth).min(axis=-1) > threshold


def tracked_error(estimates: np.ndarray, truth: np.ndarray, onsets: np.ndarray) -> float:
    """The error while tracked: the mean per-identity error over each target's frames before its first loss
    (``onsets``: :func:`loss_onsets`); NaN when every target is lost at once."""
    errors = np.linalg.norm(np.asarray(estimates) - np.asarray(truth), axis=-1)
    before = np.arange(len(errors))[:, None] < np.asarray(onsets)[None, :]
    return fsum_mean(errors[before])


def _distances(truth_k, estimates_k, threshold):
    d = np.linalg.norm(truth_k[:, None, :] - estimates_k[None, :, :], axis=-1)
    return np.where(d < threshold, d, np.nan)


def match_frames(frames):
    """CLEAR MOT's correspondences, frame by frame: for each (truth ids, hypothesis ids, distances) of
    ``frames`` (distances NaN where a pair cannot match), yield it back with its matches, a list of
    (truth index, hypothesis index, switched) into the ids, ``switched`` when the truth was last
    matched to another hypothesis (py-motmetrics' SWITCH)."""
    last = {}
    for oids, hids, d in frames:
        oids, hids = np.asarray(oids), np.asarray(hids)
        o_done, h_done = np.zeros(len(oids), bool), np.zeros(len(hids), bool)
        pairs = []
        for i, o in enumerate(oids):  # 1. keep last frame's correspondences that still hold
            if o in last:
                j = np.flatnonzero((hids == last[o]) & ~h_done)
                if len(j) and np.isfinite(d[i, j[0]]):
                    o_done[i], h_done[j[0]] = True, True
                    pairs.append((i, j[0], False))
        rest = np.array(d, dtype=float).reshape(len(oids), len(hids))
        rest[o_done, :] = np.nan
        rest[:, h_done] = np.nan
        if rest.size:
            rows, cols = linear_sum_assignment(np.where(np.isfinite(rest), rest, UNMATCHABLE))
            for i, j in zip(rows, cols):
                if np.isfinite(rest[i, j]):
                    o_done[i], h_done[j] = True, True
                    pairs.append((i, j, oids[i] in last and last[oids[i]] != hids[j]))
        for i, j, _ in pairs:
            last[oids[i]] = hids[j]
        yield oids, hids, d, pairs


def clear_mot_frames(frames) -> dict:
    """CLEAR MOT over ``frames``: (truth ids, hypothesis ids, distances) per frame, distances NaN where a pair cannot match.

    Ids may be any hashable labels.  Besides the module's counts, ``fragmentations``
    counts, per truth track, the runs of misses between its first and last match
    (py-motmetrics' ``num_fragmentations``).  The matching is :func:`match_frames`.
    """
    missed_since_match = {}  # truth id -> a miss happened after its last match
    matches = switches = misses = false_positives = fragmentations = n_truth = 0
    total_distance = 0.0
    for oids, hids, d, pairs in match_frames(frames):
        matched = np.zeros(len(oids), bool)
        for i, j, switched in pairs:
            fragmentations += missed_since_match.get(oids[i], False)
            missed_since_match[oids[i]] = False
            matched[i] = True
            total_distance += d[i, j]
            switches += switched
        for o in oids[~matched]:
            if o in missed_since_match:
                missed_since_match[o] = True
        matches += len(pairs)
        misses += len(oids) - len(pairs)
        false_positives += len(hids) - len(pairs)
        n_truth += len(oids)
    return {
        "mota": float(1.0 - (misses + false_positives + switches) / n_truth),
        "motp": total_distance / matches if matches else float("nan"),
        "switches": int(switches),
        "fragmentations": int(fragmentations),
        "misses": misses,
        "false_positives": false_positives,
        "matches": matches,
    }


def clear_mot(truth, estimates, threshold, truth_present=None, estimate_present=None) -> dict:
    """MOTA, MOTP, switches, fragmentations, misses, false positives and matches over all frames."""
    truth, estimates = np.asarray(truth, float), np.asarray(estimates, float)
    truth_present = np.ones(truth.shape[:2], bool) if truth_present is None else np.asarray(truth_present)
    estimate_present = np.ones(estimates.shape[:2], bool) if estimate_present is None else np.asarray(estimate_present)

    def frames():
        for k in range(len(truth)):
            oids, hids = np.flatnonzero(truth_present[k]), np.flatnonzero(estimate_present[k])
            yield oids, hids, _distances(truth[k, oids], estimates[k, hids], threshold)

    return clear_mot_frames(frames())


def idf1_from_counts(counts, n_truth: int, n_hypotheses: int) -> float:
    """IDF1 from ``counts[m, k]``, the frames truth track m and hypothesis track k can match."""
    counts = np.asarray(counts)
    rows, cols = linear_sum_assignment(-counts)
    return float(2 * counts[rows, cols].sum() / (n_truth + n_hypotheses))


def idf1(truth, estimates, threshold, truth_present=None, estimate_present=None) -> float:
    """IDF1 from the global truth-to-hypothesis assignment maximising matched frames."""
    truth, estimates = np.asarray(truth, float), np.asarray(estimates, float)
    truth_present = np.ones(truth.shape[:2], bool) if truth_present is None else np.asarray(truth_present)
    estimate_present = np.ones(estimates.shape[:2], bool) if estimate_present is None else np.asarray(estimate_present)
    close = np.linalg.norm(truth[:, :, None, :] - estimates[:, None, :, :], axis=-1) < threshold
    both = truth_present[:, :, None] & estimate_present[:, None, :]
    counts = (close & both).sum(axis=0)  # (M, K) frames each pair matches
    return idf1_from_counts(counts, truth_present.sum(), estimate_present.sum())
