"""Batch queries: every entry of query_many equals query at its poses, bit for bit, whatever the
pose format (Poses, N x 7 rows in either quaternion order, N x 4 x 4 matrices in float64 or
float32), the kind, the method and the threads; bad batches are caliber.Error naming the side and
row."""
import os
import pickle

import numpy as np
import pytest

import caliber

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tests", "data")
TETRA = caliber.Model.load(os.path.join(DATA, "tetra.off"))
FAN = caliber.Model.load(os.path.join(DATA, "quad_fan.off"))
# 8 triangles: with the tetrahedron, 32 pairs, more than a distance query tests without its traversal
OCTA = caliber.Model.load(os.path.join(DATA, "octahedron.off"))


def rows(n, seed):
    """n poses near the one where the fan passes through the tetrahedron: about half touch."""
    rng = np.random.default_rng(seed)
    out = np.zeros((n, 7))
    out[:, :3] = np.array([0.2, 0.2, 0.3]) + rng.uniform(-0.6, 0.6, (n, 3))
    out[:, 3:] = rng.normal(size=(n, 4))
    return out


def expect_entries(batch, poses_b, kind, tolerance, max_pairs=0, lowest_ids=False, b=FAN):
    assert len(batch) == len(poses_b)
    for i, p in enumerate(poses_b):
        r = caliber.query(TETRA, caliber.Pose(), b, p, kind=kind, tolerance=tolerance, max_pairs=max_pairs,
                          lowest_ids=lowest_ids)
        lo, hi = batch.offsets[i], batch.offsets[i + 1]
        assert batch.pairs[lo:hi].tolist() == r.pairs.tolist()
        assert (batch.entries[lo:hi] == i).all()
        assert batch.hit[i] == (len(r) > 0)
        assert batch.limit_reached[i] == r.limit_reached
        assert batch.points_a[lo:hi].tobytes() == r.points_a.tobytes()
        assert batch.points_b[lo:hi].tobytes() == r.points_b.tobytes()
        assert batch.normals[lo:hi].tobytes() == r.normals.tobytes()
        assert batch.distances[lo:hi].tobytes() == r.distances.tobytes()
        assert batch.depths[lo:hi].tobytes() == r.depths.tobytes()
        assert batch.distance[i] == (r.distances.min() if len(r) else np.inf)


@pytest.mark.parametrize("kind", ["interference", "proximity", "contact", "distance"])
@pytest.mark.parametrize("method,threads", [("sequential", 1), ("stealing", 2), ("exploitation", 2), ("hybrid", 2)])
def test_entries_equal_single_queries(kind, method, threads):
    values = rows(60, 3)
    poses = [caliber.Pose(v[:3], v[3:]) for v in values]
    tolerance = None if kind == "distance" else 0.05
    engine = caliber.Engine(method, threads)
    batch = engine.query_many(TETRA, caliber.Pose(), FAN, values, kind=kind, tolerance=tolerance)
    assert 0 < batch.hit.sum() < len(poses) or kind == "distance"
    expect_entries(batch, poses, kind, tolerance)
    limited = engine.query_many(TETRA, caliber.Pose(), FAN, poses, kind=kind, tolerance=tolerance, max_pairs=1)
    expect_entries(limited, poses, kind, tolerance, max_pairs=1)


@pytest.mark.parametrize("method,threads", [("sequential", 1), ("hybrid", 2)])
def test_distance_at_contact_first_pair_or_lowest_ids(method, threads):
    # Where the octahedron passes through the tetrahedron, several pairs are at distance 0: the
    # default reports the traversal's first, lowest_ids=True the lowest ids (never higher); both 0.
    poses = [caliber.Pose(v[:3], v[3:]) for v in rows(60, 8)]
    engine = caliber.Engine(method, threads)
    first = engine.query_many(TETRA, caliber.Pose(), OCTA, poses, kind="distance")
    lowest = engine.query_many(TETRA, caliber.Pose(), OCTA, poses, kind="distance", lowest_ids=True)
    expect_entries(first, poses, "distance", None, b=OCTA)
    expect_entries(lowest, poses, "distance", None, lowest_ids=True, b=OCTA)
    touching = first.distance == 0
    assert touching.sum() > 5 and (lowest.distance[touching] == 0).all()
    assert (first.distance[~touching] == lowest.distance[~touching]).all()
    for i in np.flatnonzero(touching):
        assert tuple(lowest.pairs[lowest.offsets[i]]) <= tuple(first.pairs[first.offsets[i]])


def test_every_pose_format_gives_the_same_batch():
    values = rows(40, 5)
    poses = [caliber.Pose(v[:3], v[3:]) for v in values]
    matrices = np.stack([p.matrix() for p in poses])
    xyzw = np.concatenate([values[:, :3], values[:, 4:], values[:, 3:4]], axis=1)
    want = caliber.query_many(TETRA, caliber.Pose(), FAN, poses, kind="proximity", tolerance=0.05)
    for given, order in ((values, "wxyz"), (xyzw, "xyzw"), (values.tolist(), "wxyz"), (memoryview(values), "wxyz")):
        got = caliber.query_many(TETRA, caliber.Pose(), FAN, given, kind="proximity", tolerance=0.05, order=order)
        assert got.pairs.tolist() == want.pairs.tolist() and got.distances.tobytes() == want.distances.tobytes()
    # Matrices give each pose through its rotation matrix: the same pairs (the last bits of a point
    # may differ, as Pose.from_matrix's do).
    from_matrices = caliber.query_many(TETRA, caliber.Pose(), FAN, matrices, kind="proximity", tolerance=0.05)
    expect_entries(from_matrices, [caliber.Pose.from_matrix(m) for m in matrices], "proximity", 0.05)
    single = caliber.query_many(TETRA, caliber.Pose(), FAN, matrices.astype(np.float32), kind="interference")
    assert len(single) == 40
    # float32 is float32 whatever dtype object carries it (an unpickled array has its own).
    unpickled = pickle.loads(pickle.dumps(matrices.astype(np.float32)))
    assert unpickled.dtype is not np.dtype(np.float32)
    again = caliber.query_many(TETRA, caliber.Pose(), FAN, unpickled, kind="interference")
    assert again.pairs.tobytes() == single.pairs.tobytes()
    assert caliber.Pose.from_matrix(unpickled[0]).matrix().tobytes() == caliber.Pose.from_matrix(matrices.astype(np.float32)[0]).matrix().tobytes()
    # Both sides moving; A given as matrices, B fixed.
    both = caliber.query_many(TETRA, matrices, FAN, matrices[::-1].copy(), kind="interference")
    assert len(both) == 40
    a_moves = caliber.query_many(TETRA, matrices, FAN, caliber.Pose(), kind="interference")
    for i, m in enumerate(matrices):
        r = caliber.query(TETRA, caliber.Pose.from_matrix(m), FAN, caliber.Pose())
        assert a_moves.pairs[a_moves.offsets[i]:a_moves.offsets[i + 1]].tolist() == r.pairs.tolist()


def test_bad_batches_are_caliber_errors_naming_the_row():
    values = rows(5, 7)
    values[3, 3:] = 0.0
    with pytest.raises(caliber.Error, match=r"poses_b\[3\]: quaternion is \(nearly\) zero"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, values)
    bad = np.stack([np.eye(4)] * 3)
    bad[1, 0, 1] = 0.3
    with pytest.raises(caliber.Error, match=r"poses_a\[1\]: is not a rigid transform"):
        caliber.query_many(TETRA, bad, FAN, caliber.Pose())
    with pytest.raises(caliber.Error, match="3 poses of A but 5 of B"):
        caliber.query_many(TETRA, np.stack([np.eye(4)] * 3), FAN, rows(5, 8))
    with pytest.raises(caliber.Error, match="must be 4 x 4, N x 4 x 4, 7 or N x 7"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, np.zeros((3, 6)))
    with pytest.raises(caliber.Error, match=r"poses_b\[1\]: must be a caliber.Pose"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, [caliber.Pose(), "x"])
    with pytest.raises(caliber.Error, match="poses_b: must be a caliber.Pose, a list of them"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, "poses")
    # Buffers are read as arrays, whatever their length: an empty one is not 0 poses.
    with pytest.raises(caliber.Error, match="poses_b: must be a caliber.Pose, a list of them"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, b"")
    with pytest.raises(caliber.Error, match="poses_b: an array of poses must be 4 x 4"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, memoryview(np.zeros((0, 3))))
    with pytest.raises(caliber.Error, match="order: must be 'wxyz' or 'xyzw'"):
        caliber.query_many(TETRA, caliber.Pose(), FAN, rows(2, 1), order="zyxw")
    with pytest.raises(caliber.Error, match="Batch: was never built"):
        caliber.Batch.__new__(caliber.Batch).hit
    empty = caliber.query_many(TETRA, caliber.Pose(), FAN, np.zeros((0, 7)))
    assert len(empty) == 0 and empty.offsets.tolist() == [0]


FIELDS = ["offsets", "hit", "limit_reached", "distance", "pairs", "entries", "points_a", "points_b", "normals",
          "distances", "depths"]


def test_batches_pickle_and_concatenate_to_the_whole_batch():
    values = rows(60, 4)
    whole = caliber.query_many(TETRA, caliber.Pose(), FAN, values, kind="proximity", tolerance=0.05, max_pairs=2)
    assert whole.limit_reached.any() and 0 < whole.hit.sum() < 60
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        again = pickle.loads(pickle.dumps(whole, protocol))
        for name in FIELDS:
            assert getattr(again, name).tobytes() == getattr(whole, name).tobytes(), name
        assert (again.node_tests, again.leaf_tests) == (whole.node_tests, whole.leaf_tests)
    parts = [caliber.query_many(TETRA, caliber.Pose(), FAN, values[lo:hi], kind="proximity", tolerance=0.05, max_pairs=2)
             for lo, hi in [(0, 0), (0, 17), (17, 18), (18, 60)]]
    joined = caliber.Batch.concatenate(parts)
    for name in FIELDS:
        assert getattr(joined, name).tobytes() == getattr(whole, name).tobytes(), name
    assert len(caliber.Batch.concatenate([])) == 0


def test_tampered_batch_states_are_refused():
    whole = caliber.query_many(TETRA, caliber.Pose(), FAN, rows(10, 4), kind="proximity", tolerance=0.05)
    state = list(whole.__reduce__()[1][0])
    assert len(whole.pairs) > 0

    def refused(change, match):
        s = list(state)
        change(s)
        with pytest.raises(caliber.Error, match="not a caliber.Batch state: " + match):
            caliber._batch_from_state(tuple(s))

    refused(lambda s: s.pop(), "expected a tuple of 10 items")
    refused(lambda s: s.__setitem__(0, s[0][::-1].copy()), "offsets must not decrease")
    refused(lambda s: s.__setitem__(0, s[0] + 1), "offsets must start at 0")
    refused(lambda s: s.__setitem__(0, np.array([0, 10**15])), "distances must have offsets")
    refused(lambda s: s.__setitem__(2, s[2][:-1]), "pairs does not have the shape")
    refused(lambda s: s.__setitem__(1, s[1][:-1]), "limit_reached does not have the shape")
    refused(lambda s: s.__setitem__(3, "points"), "points_a")
    refused(lambda s: s.__setitem__(8, -1), "the counters must be integers")


def test_a_batch_cannot_be_changed_through_its_arrays():
    whole = caliber.query_many(TETRA, caliber.Pose(), FAN, rows(20, 4), kind="proximity", tolerance=0.05)
    assert len(whole.pairs) > 0
    before = {name: getattr(whole, name).tobytes() for name in FIELDS}
    for name in FIELDS:
        view = getattr(whole, name)
        with pytest.raises(ValueError, match="read-only"):
            view[...] = 0
        with pytest.raises(ValueError):
            view.flags.writeable = True
        # The view's shape and dtype are its own: the batch's arrays keep theirs.
        view.shape = (-1,)
        view.dtype = np.uint8
    # Nor through a view's base (the Batch itself) or a pickled state (copies).
    view = whole.distances
    assert view.base is whole
    state = whole.__reduce__()[1][0]
    state[6].dtype = np.int8
    state[0][...] = 0
    for name in FIELDS:
        assert getattr(whole, name).tobytes() == before[name], name
    joined = caliber.Batch.concatenate([whole, whole])
    assert joined.offsets.tolist() == whole.offsets.tolist() + (whole.offsets[1:] + whole.offsets[-1]).tolist()
    assert joined.pairs.tolist() == whole.pairs.tolist() * 2


def test_type_errors_are_one_line_of_bounded_length():
    poses = rows(100000, 1).tolist()
    calls = [
        (lambda: caliber.query_many(TETRA, caliber.Pose(), FAN, poses, max_pairs=-1), ["list of length 100000", "max_pairs=-1"]),
        (lambda: caliber.Engine(threads=1).query_many(TETRA, caliber.Pose(), FAN, np.asarray(poses), kind=None),
         ["numpy.ndarray of length 100000", "kind=None"]),
        (lambda: caliber.query(TETRA, [0.0] * 100000, FAN, caliber.Pose()), ["list of length 100000"]),
        (lambda: caliber.Engine(threads="x" * 100000), ["str of length 100000"]),
        (lambda: caliber.Batch.concatenate([1] * 100000), ["list of length 100000"]),
    ]
    for call, shown in calls:
        with pytest.raises(TypeError, match="incompatible (function|constructor) arguments") as raised:
            call()
        text = str(raised.value)
        assert "\n" not in text and len(text) < 2000, text[:200]
        for part in shown:
            assert part in text, (part, text)



def _interrupting(call):
    """Runs call() with SIGINT sent 0.2 s in, a handler raising Interrupted: whether the call raised
    it, and the seconds the call took."""
    import signal
    import threading
    import time

    class Interrupted(Exception):
        pass

    def handler(signum, frame):
        raise Interrupted()

    previous = signal.signal(signal.SIGINT, handler)
    timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    raised = False
    try:
        timer.start()
        call()
    except Interrupted:
        raised = True
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    return raised, time.perf_counter() - start


def _seconds(call):
    import time
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def test_a_long_batch_or_sweep_call_stops_on_ctrl_c():
    # A tenth of each call is timed whole; the call itself, stopped 0.2 s in, must end well before
    # the whole would (without the check between chunks, the handler ran only once it returned).
    far = np.zeros((4000000, 7))  # four million distance entries: seconds of work
    far[:, 0] = 3.0
    far[:, 3] = 1.0
    start = np.zeros((1000000, 7))
    start[:, 0] = 3.0
    start[:, 3] = 1.0
    end = start.copy()
    end[:, 0] = -3.0
    engine = caliber.Engine(threads=2)
    calls = [
        lambda n: engine.query_many(TETRA, caliber.Pose(), FAN, far[:n], kind="distance"),
        lambda n: caliber.query_many(TETRA, caliber.Pose(), FAN, far[:n], kind="distance"),
        lambda n: caliber.sweep_many(TETRA, caliber.Pose(), caliber.Pose(), FAN, start[:n], end[:n]),
    ]
    for call, n in zip(calls, (len(far), len(far), len(start))):
        tenth = _seconds(lambda: call(n // 10))
        raised, took = _interrupting(lambda: call(n))
        assert raised
        assert took < 5 * tenth + 0.5, (took, tenth)
    # The engine takes its next call as usual, with the same answers.
    batch = engine.query_many(TETRA, caliber.Pose(), FAN, far[:3], kind="distance")
    one = caliber.query(TETRA, caliber.Pose(), FAN, caliber.Pose([3.0, 0, 0], [1, 0, 0, 0]), kind="distance")
    assert batch.distances.tolist() == [one.distances[0]] * 3
