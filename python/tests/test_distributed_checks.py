"""caliber.distributed.query_many checks its arguments on the calling machine, before anything is
sent to the cluster: a client that records what it is asked shows that a bad request sends nothing,
and numpy integers are integers. (The sweeps themselves, on a real cluster: python/tests_distributed.)"""
import os

import numpy as np
import pytest

import caliber
import caliber.distributed

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tests", "data")
TETRA = caliber.Model.load(os.path.join(DATA, "tetra.off"))
FAN = caliber.Model.load(os.path.join(DATA, "quad_fan.off"))


class Future:
    def __init__(self, value):
        self.value = value


class RecordingClient:
    """dask.distributed.Client's three calls query_many makes, run here, and counted."""

    def __init__(self):
        self.calls = []

    def scatter(self, data, broadcast=False, hash=True):
        self.calls.append("scatter")
        return data

    def submit(self, function, *args, pure=True):
        self.calls.append("submit")
        return Future(function(*args))

    def gather(self, futures):
        return [f.value for f in futures]


def rows(n):
    out = np.zeros((n, 7))
    out[:, :3] = np.linspace(-1.0, 1.0, n)[:, None]
    out[:, 3] = 1.0
    return out


def test_numpy_integers_are_chunk_sizes():
    values = rows(60)
    want = caliber.query_many(TETRA, caliber.Pose(), FAN, values, kind="proximity", tolerance=0.05)
    for chunk in (np.int64(25), np.int32(25), np.uint8(25), 25):
        client = RecordingClient()
        got = caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, values, kind="proximity",
                                             tolerance=0.05, chunk=chunk)
        assert client.calls.count("submit") == 3, chunk
        assert got.offsets.tobytes() == want.offsets.tobytes() and got.pairs.tobytes() == want.pairs.tobytes()


@pytest.mark.parametrize("chunk,message", [(0, "not 0"), (np.int64(-3), "not -3"), (True, "not bool True"),
                                           (2.0, "not float 2.0"), ("25", "not str '25'"), (None, "not NoneType None")])
def test_bad_chunk_sizes_name_the_value_and_send_nothing(chunk, message):
    client = RecordingClient()
    with pytest.raises(caliber.Error, match=f"^chunk: must be an integer >= 1, {message}$"):
        caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, rows(10), chunk=chunk)
    assert client.calls == []


@pytest.mark.parametrize("request_args,message", [
    (dict(kind="collide"), "^kind: unknown query kind 'collide'"),
    (dict(kind="proximity", tolerance=-1.0), "^tolerance: "),
    (dict(kind="proximity", tolerance=1e300), "^tolerance: must be at most 1e15"),
    (dict(kind="contact", tolerance=0.1, angle=500.0), "^angle: "),
    (dict(order="zyxw"), "^order: must be 'wxyz' or 'xyzw'"),
    (dict(threads=-1), "^threads: "),
])
def test_a_bad_request_is_one_error_before_anything_is_sent(request_args, message):
    client = RecordingClient()
    with pytest.raises(caliber.Error, match=message):
        caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, rows(10), chunk=4, **request_args)
    assert client.calls == []


def test_arguments_of_the_wrong_type_send_nothing():
    client = RecordingClient()
    with pytest.raises(TypeError):
        caliber.distributed.query_many(client, TETRA, caliber.Pose(), FAN, rows(10), max_pairs=-1)
    assert client.calls == []
