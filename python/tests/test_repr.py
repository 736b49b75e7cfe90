"""repr() of every class says what the object holds: counts, kind, status, method and threads; a
Pose's repr is the call that makes it again (its quaternion normalized again, so to rounding); an
object made by __new__ alone says it was never built."""
import os
import random

import numpy as np
import pytest

import caliber

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "data")
TETRA = os.path.join(DATA, "tetra.off")


def tetra():
    return caliber.Model.load(TETRA)


def test_mesh_and_model():
    mesh = caliber.Mesh(np.eye(3), [[0, 1, 2]])
    assert repr(mesh) == "<caliber.Mesh: 3 vertices, 1 triangle>"
    model = caliber.Model(mesh, adjacency=False, oriented_boxes=True)
    assert repr(model) == f"<caliber.Model: 1 triangle, BVH height {model.height}, oriented boxes>"
    big = tetra()
    assert repr(big) == f"<caliber.Model: {big.triangles} triangles, BVH height {big.height}, adjacency>"


def test_pose_repr_makes_the_same_pose():
    pose = caliber.Pose((1.5, -0.25, 1e-17), (0.3, 0.1, -0.2, 0.9))
    assert repr(pose).startswith("caliber.Pose((1.5, -0.25, 1e-17), (")
    assert repr(caliber.Pose()) == "caliber.Pose((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))"
    rng = random.Random(7)
    for _ in range(200):
        pose = caliber.Pose([rng.uniform(-1e3, 1e3) for _ in range(3)], [rng.uniform(-1, 1) for _ in range(4)])
        again = eval(repr(pose), {"caliber": caliber})
        assert again.translation == pose.translation
        assert np.allclose(again.quaternion, pose.quaternion, rtol=0, atol=4e-16)


def test_repr_of_another_type_is_a_short_type_error():
    with pytest.raises(TypeError, match="takes a caliber.Pose, not list"):
        caliber.Pose.__repr__([0] * 100000)


def test_never_built_objects_say_so():
    for cls in (caliber.Mesh, caliber.Model, caliber.Pose, caliber.Result, caliber.Batch, caliber.Sweep, caliber.Sweeps,
                caliber.Engine, caliber.World):
        assert repr(cls.__new__(cls)) == f"<caliber.{cls.__name__}: never built>"


def test_result_names_its_kind_and_counts():
    a = tetra()
    r = caliber.query(a, caliber.Pose(), a, caliber.Pose((0.2, 0.1, 0.1)), kind="proximity", tolerance=0.01)
    assert len(r) > 1
    assert repr(r) == (f"<caliber.Result: proximity, {len(r)} pairs, {r.node_tests} node tests, "
                       f"{r.leaf_tests} leaf tests>")
    cut = caliber.query(a, caliber.Pose(), a, caliber.Pose((0.2, 0.1, 0.1)), max_pairs=1)
    assert cut.limit_reached and repr(cut).endswith(", limit reached>") and cut.kind == "interference"
    apart = caliber.query(a, caliber.Pose(), a, caliber.Pose((5, 0, 0)))
    assert repr(apart).startswith("<caliber.Result: interference, 0 pairs, ")


def test_batch_sweep_and_sweeps():
    a = tetra()
    poses = [caliber.Pose((0.2, 0.1, 0.1)), caliber.Pose((5, 0, 0)), caliber.Pose((6, 0, 0))]
    batch = caliber.query_many(a, caliber.Pose(), a, poses)
    assert repr(batch) == f"<caliber.Batch: 3 entries, 1 hit, {len(batch.pairs)} pairs>"
    still, far, near = caliber.Pose(), caliber.Pose((5, 0, 0)), caliber.Pose((0.5, 0, 0))
    hit = caliber.sweep(a, still, still, a, far, near)
    assert hit.status == "contact"
    assert repr(hit) == (f"<caliber.Sweep: contact at t={hit.time!r}, pair {hit.pair}, {hit.queries} queries>")
    free = caliber.sweep(a, still, still, a, far, far)
    assert repr(free) == f"<caliber.Sweep: free, {free.queries} quer{'y' if free.queries == 1 else 'ies'}>"
    sweeps = caliber.sweep_many(a, still, still, a, [far, far], [near, far])
    assert repr(sweeps) == "<caliber.Sweeps: 2 motions, 1 contact, 0 undecided>"


def test_engine_and_world():
    engine = caliber.Engine("hybrid", threads=1)
    assert repr(engine) == "<caliber.Engine: method hybrid, 1 thread>"
    assert engine.method == "hybrid"
    world = caliber.World(os.path.join(DATA, "scenes", "tetras.json"))
    assert repr(world) == f"<caliber.World: {len(world.objects)} objects, {world.steps} steps>"
