"""caliber.distributed on a LocalCluster of 2 worker processes: a pose batch's Batch equals
caliber.query_many's bit for bit (every pose format, either side fixed, chunk sizes that do and do
not divide the poses), bad batches are caliber.Error naming the row in the whole batch, and a
worker killed mid-batch costs a re-run of its chunks, not the batch. Run by scripts/test.sh (not by the
sanitizer builds: the workers are separate interpreters)."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import caliber
import caliber.distributed

distributed = pytest.importorskip("distributed")

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tests", "data")
TETRA = caliber.Model.load(os.path.join(DATA, "tetra.off"))
FAN = caliber.Model.load(os.path.join(DATA, "quad_fan.off"))
FIELDS = ["offsets", "hit", "limit_reached", "distance", "pairs", "entries", "points_a", "points_b", "normals",
          "distances", "depths"]


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def rows(n, seed, spread=0.6):
    rng = np.random.default_rng(seed)
    out = np.zeros((n, 7))
    out[:, :3] = np.array([0.2, 0.2, 0.3]) + rng.uniform(-spread, spread, (n, 3))
    out[:, 3:] = rng.normal(size=(n, 4))
    return out


def expect_same(got, want):
    assert len(got) == len(want)
    for name in FIELDS:
        assert getattr(got, name).tobytes() == getattr(want, name).tobytes(), name
    # (The counters are the work done: a small chunk's entries may be split, as a small batch's are.)


@pytest.mark.parametrize("kind,tolerance", [("interference", None), ("proximity", 0.05), ("distance", None)])
@pytest.mark.parametrize("chunk", [7, 100, 1000])
def test_batch_equals_query_many(client, kind, tolerance, chunk):
    values = rows(300, 3)
    want = caliber.query_many(TETRA, caliber.Pose(), FAN, values, kind=kind, tolerance=tolerance, threads=1)
    got = caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, values, kind=kind, tolerance=tolerance,
                                         chunk=chunk)
    assert 0 < want.hit.sum() < len(values) or kind == "distance"
    expect_same(got, want)


def test_every_pose_format_and_either_side_fixed(client):
    values = rows(50, 5)
    poses = [caliber.Pose(v[:3], v[3:]) for v in values]
    matrices = np.stack([p.matrix() for p in poses])
    xyzw = values[:, [0, 1, 2, 4, 5, 6, 3]]
    want = caliber.query_many(TETRA, caliber.Pose(), FAN, poses, kind="proximity", tolerance=0.05)
    for given, order in [(poses, "wxyz"), (matrices, "wxyz"), (matrices.astype(np.float32), "wxyz"), (xyzw, "xyzw")]:
        want_here = caliber.query_many(TETRA, caliber.Pose(), FAN, given, kind="proximity", tolerance=0.05, order=order)
        got = caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, given, kind="proximity",
                                             tolerance=0.05, order=order, chunk=16)
        expect_same(got, want_here)
    expect_same(caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, poses, kind="proximity",
                                               tolerance=0.05, chunk=16), want)
    # A moves, B fixed; both move.
    fixed = caliber.Pose([0.2, 0.2, 0.3], [1, 0, 0, 0])
    expect_same(caliber.distributed.query_many(client, TETRA, values, FAN, fixed, chunk=9),
                caliber.query_many(TETRA, values, FAN, fixed))
    expect_same(caliber.distributed.query_many(client, TETRA, values, FAN, values[::-1].copy(), chunk=9),
                caliber.query_many(TETRA, values, FAN, values[::-1].copy()))
    assert len(caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, [])) == 0


def test_bad_batches_are_errors_naming_the_row(client):
    values = rows(40, 7)
    values[33, 3:] = 0.0  # a zero quaternion, in the fourth chunk of 10
    with pytest.raises(caliber.Error, match=r"poses_b\[33\]"):
        caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, values, chunk=10)
    with pytest.raises(caliber.Error, match="3 poses of A but 2 of B"):
        caliber.distributed.query_many(client, TETRA, rows(3, 1), FAN, rows(2, 2))
    with pytest.raises(caliber.Error, match="chunk"):
        caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, values, chunk=0)
    with pytest.raises(caliber.Error, match="poses_b"):
        caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, np.zeros((5, 6)))
    with pytest.raises(caliber.Error, match="^poses_a: must be a caliber.Pose"):  # ragged rows
        caliber.distributed.query_many(client, TETRA, [[0, 0, 0, 1, 0, 0, 0], [0, 0, 1]], FAN, caliber.Pose())


def torus(rings, sides):
    """A torus of 2 * rings * sides triangles (radii 1 and 0.35)."""
    u, v = np.meshgrid(np.arange(rings) * 2 * np.pi / rings, np.arange(sides) * 2 * np.pi / sides, indexing="ij")
    r = 1.0 + 0.35 * np.cos(v)
    vertices = np.stack([r * np.cos(u), r * np.sin(u), 0.35 * np.sin(v)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(rings), np.arange(sides), indexing="ij")
    k00, k10 = i * sides + j, (i + 1) % rings * sides + j
    k01, k11 = i * sides + (j + 1) % sides, (i + 1) % rings * sides + (j + 1) % sides
    faces = np.concatenate([np.stack([k00, k10, k11], -1).reshape(-1, 3), np.stack([k00, k11, k01], -1).reshape(-1, 3)])
    return caliber.Model(caliber.Mesh(vertices, faces))


def test_a_killed_worker_costs_its_chunks_not_the_batch(client):
    # 20 chunks of a few tenths of a second each; one worker is killed once the batch is under way
    # (its nanny starts another), and the batch still gives query_many's Batch.
    a = torus(120, 60)
    values = rows(60000, 11, spread=1.2)
    want = caliber.query_many(a, caliber.Pose(), FAN, values, kind="distance", threads=1)
    pids = client.run(os.getpid)
    victim = sorted(pids)[0]

    def kill_when_started():
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and not any(client.processing().values()):
            time.sleep(0.01)
        time.sleep(0.3)
        os.kill(pids[victim], signal.SIGKILL)
        killed.append(time.monotonic())

    killed = []
    killer = threading.Thread(target=kill_when_started)
    killer.start()
    got = caliber.distributed.query_many(client, a, caliber.Pose(), FAN, values, kind="distance", chunk=len(values) // 20)
    finished = time.monotonic()
    killer.join()
    assert killed and killed[0] < finished, "the worker was killed while the batch ran"
    expect_same(got, want)
    client.wait_for_workers(2, timeout=60)
    assert pids[victim] not in client.run(os.getpid).values(), "the killed worker was replaced"
