"""Pose batches over a Dask cluster (dask.distributed): caliber.query_many's answers, computed in
chunks of poses on the cluster's workers, gathered in input order.

    from dask.distributed import Client
    import caliber
    import caliber.distributed

    client = Client("tcp://scheduler-host:8786")  # or Client() for a cluster on this machine
    batch = caliber.distributed.query_many(client, robot, caliber.Pose(), obstacle, poses, kind="distance")

Each model goes to every worker once (client.scatter with broadcast), the poses in chunks of
`chunk` entries, each chunk one Dask job: caliber.query_many on the worker with `threads` threads.
The chunks' Batches come back and are joined in order into one Batch, equal bit for bit to
caliber.query_many's on one machine. A worker that dies mid-batch costs the chunks it held: the
scheduler runs them again on the workers left (up to Dask's distributed.scheduler.allowed-failures
times per chunk).
"""
import operator
import re

import numpy as np

import caliber

_ROW = re.compile(r"^(poses_[ab])\[(\d+)\]")


def _positive_integer(value, name):
    """`value` as an int >= 1: a Python or numpy integer (not a bool, not a float)."""
    try:
        if isinstance(value, (bool, np.bool_)):
            raise TypeError
        number = operator.index(value)
    except TypeError:
        raise caliber.Error(f"{name}: must be an integer >= 1, not {type(value).__name__} {value!r}") from None
    if number < 1:
        raise caliber.Error(f"{name}: must be an integer >= 1, not {number}")
    return number


def _run_chunk(a, poses_a, b, poses_b, first, request):
    """One chunk on a worker; a bad pose's error names its row in the whole batch."""
    try:
        return caliber.query_many(a, poses_a, b, poses_b, **request)
    except caliber.Error as e:
        message = _ROW.sub(lambda m: f"{m.group(1)}[{int(m.group(2)) + first}]", str(e), count=1)
        raise caliber.Error(message) from None


def _side(poses, name):
    """(count, take): how many poses a side gives (1: the same pose for every entry, which take
    gives whatever the rows asked) and how to cut rows [lo, hi) of it."""
    if isinstance(poses, caliber.Pose):
        return 1, lambda lo, hi: poses
    if isinstance(poses, (list, tuple)) and (len(poses) == 0 or isinstance(poses[0], caliber.Pose)):
        if len(poses) == 1:
            return 1, lambda lo, hi: poses
        return len(poses), lambda lo, hi: list(poses[lo:hi])
    try:
        values = np.asarray(poses)
    except (ValueError, TypeError) as e:  # ragged lists, objects numpy cannot read
        raise caliber.Error(f"{name}: must be a caliber.Pose, a list of them, or an array of N x 4 x 4 matrices or N x 7 "
                            f"rows ({str(e).splitlines()[0][:200]})") from None
    if values.shape in ((4, 4), (7,)):
        return 1, lambda lo, hi: values
    if (values.ndim == 3 and values.shape[1:] == (4, 4)) or (values.ndim == 2 and values.shape[1] == 7):
        if values.shape[0] == 1:
            return 1, lambda lo, hi: values
        return values.shape[0], lambda lo, hi: values[lo:hi]
    raise caliber.Error(f"{name}: an array of poses must be 4 x 4, N x 4 x 4, 7 or N x 7 (translation and quaternion)")


def query_many(client, a, poses_a, b, poses_b, kind="interference", tolerance=None, angle=30.0, max_pairs=0, *,
               order="wxyz", lowest_ids=False, chunk=2500, threads=1):
    """caliber.query_many(a, poses_a, b, poses_b, ...) on the workers of `client` (a
    dask.distributed Client): the same arguments and the same Batch, bit for bit. `chunk`: poses
    per Dask job (a dead worker's chunks run again); `threads`: threads per chunk on its worker (1 fits
    workers started with one thread per core)."""
    chunk = _positive_integer(chunk, "chunk")
    if not isinstance(a, caliber.Model) or not isinstance(b, caliber.Model):
        raise caliber.Error("a, b: must be caliber.Model")
    na, take_a = _side(poses_a, "poses_a")
    nb, take_b = _side(poses_b, "poses_b")
    if na != 1 and nb != 1 and na != nb:
        raise caliber.Error(f"poses_a: {na} poses of A but {nb} of B (each side gives one pose or one per entry)")
    n = max(na, nb) if na != 0 and nb != 0 else 0
    request = dict(kind=kind, tolerance=tolerance, angle=angle, max_pairs=max_pairs, order=order,
                   lowest_ids=lowest_ids, threads=threads)
    # The request checked here, before anything is sent: a bad kind, tolerance, angle, max_pairs,
    # order, lowest_ids or threads is one error from this machine, not one from every chunk.
    caliber.query_many(a, np.empty((0, 7)), b, np.empty((0, 7)), **request)
    if n == 0:  # nothing to send: the empty Batch, from this machine
        return caliber.query_many(a, take_a(0, 0), b, take_b(0, 0), **request)
    model_a, model_b = client.scatter([a, b], broadcast=True, hash=False)
    futures = []
    for lo in range(0, n, chunk):
        hi = min(n, lo + chunk)
        futures.append(client.submit(_run_chunk, model_a, take_a(lo, hi), model_b, take_b(lo, hi), lo, request, pure=False))
    return caliber.Batch.concatenate(client.gather(futures))
