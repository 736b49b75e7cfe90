"""The Python bindings: the same pairs and contacts as the C++ API (through the caliber CLI's JSON,
which prints every double exactly), bit for bit; meshes from arrays; poses from matrices; the
engine over in-memory frames and scenes; pickled models; errors as caliber.Error."""
import inspect
import json
import os
import pathlib
import pickle
import subprocess
import threading

import numpy as np
import pytest

import caliber

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "data")
CLI = os.environ.get("CALIBER_CLI", os.path.join(ROOT, "build", "caliber"))
TETRA = os.path.join(DATA, "tetra.off")
FAN = os.path.join(DATA, "quad_fan.off")
POSE = (0.2, 0.2, 0.3, 0.0, 1.0, 0.0, 0.0)  # B turned over and pushed into A: pairs of every kind


def pose(values):
    return caliber.Pose(values[:3], values[3:])


def cli_query(a, b, values, kind, tolerance):
    out = subprocess.run([CLI, "query", a, b, "--pose-b", " ".join(repr(v) for v in values), "--kind", kind,
                          "--tolerance", repr(tolerance), "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


@pytest.mark.parametrize("kind", ["interference", "proximity", "contact", "distance"])
def test_query_equals_the_cpp_api_bit_for_bit(kind):
    a, b = caliber.Model.load(TETRA), caliber.Model.load(FAN)
    r = caliber.query(a, caliber.Pose(), b, pose(POSE), kind=kind, tolerance=0.3)
    want = cli_query(TETRA, FAN, POSE, kind, 0.3)
    assert len(want["pairs"]) > 0
    assert r.pairs.tolist() == want["pairs"]
    assert r.node_tests == want["stats"]["node_tests"] and r.leaf_tests == want["stats"]["leaf_tests"]
    if kind == "interference":
        assert not r.distances.any()
        return
    for i, c in enumerate(want["contacts"]):
        assert r.points_a[i].tolist() == c["point_a"]
        assert r.points_b[i].tolist() == c["point_b"]
        assert r.normals[i].tolist() == c["normal"]
        assert r.distances[i] == c["distance"]


def test_query_takes_its_arguments_in_every_form_alike():
    # Python floats, ints, bools and str are read by the vectorcall path, numpy scalars by
    # pybind11's; by position or by name, in any order: one answer.
    a, b = caliber.Model.load(TETRA), caliber.Model.load(FAN)
    ident, pb = caliber.Pose(), pose(POSE)
    # Each argument read changes the answer: the tolerance (8 pairs within 0.05, 16 within 0.3),
    # the angle (2 contacts at 90 degrees, 1 at 30).
    assert len(caliber.query(a, ident, b, pb, "proximity", 0.05)) != len(caliber.query(a, ident, b, pb, "proximity", 0.3))
    assert len(caliber.query(a, ident, b, pb, "contact", 0.3, 90.0)) != len(caliber.query(a, ident, b, pb, "contact", 0.3))
    for kind, tolerance, angle in [("proximity", 0.05, 30.0), ("contact", 0.3, 90.0), ("distance", None, 30.0)]:
        want = caliber.query(a, ident, b, pb, kind=kind, tolerance=tolerance, angle=angle)
        assert len(want) > 0
        forms = [
            caliber.query(a, ident, b, pb, kind, tolerance, angle, 0),
            caliber.query(b=b, pose_b=pb, a=a, angle=angle, pose_a=ident, tolerance=tolerance, kind=kind, lowest_ids=False),
            caliber.query(a, ident, b, pb, np.str_(kind), None if tolerance is None else np.float32(tolerance),
                          np.float64(angle), np.int64(0), lowest_ids=np.bool_(False)),
        ]
        for got in forms:
            for name in ["pairs", "points_a", "points_b", "normals", "distances", "depths"]:
                assert getattr(got, name).tobytes() == getattr(want, name).tobytes(), (kind, name)
            assert (got.node_tests, got.leaf_tests) == (want.node_tests, want.leaf_tests)
    assert len(caliber.query(a, ident, b, pb, "proximity", 1)) == len(caliber.query(a, ident, b, pb, "proximity", 1.0))
    assert caliber.query(a, ident, b, pb, max_pairs=1).limit_reached
    # Calls it does not take are answered by pybind11's checks, as before.
    with pytest.raises(TypeError, match="incompatible function arguments"):
        caliber.query(a, ident, b)
    with pytest.raises(TypeError, match="incompatible function arguments"):
        caliber.query(a, ident, b, pb, tolerence=0.1)
    with pytest.raises(TypeError, match="incompatible function arguments"):
        caliber.query(a, ident, b, pb, "distance", 0.1, 30.0, 0, True)  # lowest_ids is keyword-only
    with pytest.raises(TypeError, match="incompatible function arguments"):
        caliber.query(a, ident, b, pb, max_pairs=-1)
    with pytest.raises(caliber.Error, match="unknown query kind 'nope'"):
        caliber.query(a, ident, b, pb, kind="nope")
    with pytest.raises(caliber.Error, match="tolerance: must be a finite number >= 0"):
        caliber.query(a, ident, b, pb, tolerance=float("nan"))
    assert str(inspect.signature(caliber.query)) == (
        "(a, pose_a, b, pose_b, kind='interference', tolerance=None, angle=30.0, max_pairs=0, *, lowest_ids=False)")
    assert pickle.loads(pickle.dumps(caliber.query)) is caliber.query


@pytest.mark.parametrize("where", [(1.5, 0.2, 0.1), (0.2, 0.2, 0.2)])
def test_result_arrays_are_made_once_whatever_is_read_first(where):
    model = caliber.Model.load(TETRA)
    pose = caliber.Pose(list(where), [1, 0, 0, 0])
    first = caliber.query(model, caliber.Pose(), model, pose, kind="proximity", tolerance=0.05)
    again = caliber.query(model, caliber.Pose(), model, pose, kind="proximity", tolerance=0.05)
    n = len(first)
    assert (n == 0) == (where[0] > 1)
    assert first.distances is first.distances  # made on the first read, then kept
    assert first.pairs.shape == (n, 2) and first.points_a.shape == (n, 3) and first.depths.shape == (n,)
    assert len(first) == n
    # Read in another order, the same rows.
    for name in ["depths", "normals", "points_b", "points_a", "pairs", "objects", "distances"]:
        assert getattr(again, name).tobytes() == getattr(first, name).tobytes()


def test_meshes_from_arrays_equal_meshes_from_files():
    m = caliber.Mesh.load(FAN)
    again = caliber.Mesh(m.vertices, m.faces)
    assert np.array_equal(again.vertices, m.vertices) and np.array_equal(again.faces, m.faces)
    a = caliber.query(caliber.Model(m), caliber.Pose(), caliber.Model.load(TETRA), pose(POSE), kind="proximity", tolerance=0.3)
    b = caliber.query(caliber.Model(again), caliber.Pose(), caliber.Model.load(TETRA), pose(POSE), kind="proximity", tolerance=0.3)
    assert a.pairs.tolist() == b.pairs.tolist() and np.array_equal(a.points_a, b.points_a)
    with pytest.raises(caliber.Error, match="arrays: face 0 refers to vertex 9"):
        caliber.Mesh(m.vertices, np.array([[0, 1, 9]]))
    # uint64 indices past int64 are named as given (cast, 2**64 - 1 read as -1).
    wide = np.array([[0, 1, 2], [0, 1, 2**64 - 1], [2**63, 1, 2]], dtype=np.uint64)
    with pytest.raises(caliber.Error, match=r"^arrays: face 1 refers to vertex 18446744073709551615 but there are only \d+$"):
        caliber.Mesh(m.vertices, wide)
    with pytest.raises(caliber.Error, match="arrays: face 1 refers to vertex 9223372036854775808 "):
        caliber.Mesh(m.vertices, wide[[0, 2]])
    assert np.array_equal(caliber.Mesh(m.vertices, m.faces.astype(np.uint64)).faces, m.faces)
    with pytest.raises(ValueError, match="n x 3"):
        caliber.Mesh(np.zeros((3, 2)), m.faces)


def test_pose_from_a_matrix_round_trips():
    p = pose(POSE)
    q = caliber.Pose.from_matrix(p.matrix())
    assert np.allclose(q.matrix(), p.matrix(), atol=1e-15)
    with pytest.raises(caliber.Error, match="not a rigid transform"):
        caliber.Pose.from_matrix(np.diag([2.0, 1.0, 1.0, 1.0]))


def test_pose_from_a_float32_matrix_and_quaternion_orders():
    p = caliber.Pose((0.1, -0.2, 0.3), (0.9, 0.1, -0.3, 0.2))  # no entry of its matrix is exact in float32
    with pytest.raises(caliber.Error, match="not a rigid transform within 1e-09"):
        caliber.Pose.from_matrix(p.matrix().astype(np.float32).astype(np.float64))  # the same values as float64
    q = caliber.Pose.from_matrix(p.matrix().astype(np.float32))  # a rotation only to float32's rounding
    assert np.allclose(q.matrix(), p.matrix(), atol=1e-6)
    with pytest.raises(caliber.Error, match="not a rigid transform"):
        caliber.Pose.from_matrix(np.round(p.matrix(), 4))  # float64: within 1e-9
    w, x, y, z = p.quaternion
    assert np.allclose(caliber.Pose(p.translation, (x, y, z, w), order="xyzw").matrix(), p.matrix(), atol=1e-15)
    assert np.allclose(caliber.Pose.from_quaternion((x, y, z, w), "xyzw", p.translation).matrix(), p.matrix(), atol=1e-15)
    assert np.allclose(p.as_quaternion("xyzw"), (x, y, z, w)) and np.allclose(p.as_quaternion("wxyz"), (w, x, y, z))
    turned = caliber.Pose.from_quaternion((0.0, 0.0, 1.0, 0.0), "xyzw")  # scipy's order: half a turn about z
    assert np.allclose(turned.matrix()[:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-15)
    with pytest.raises(caliber.Error, match="order: must be 'wxyz' or 'xyzw'"):
        caliber.Pose.from_quaternion((0.0, 0.0, 0.0, 1.0), "zyxw")


def test_poses_refuse_numbers_that_are_not_real():
    # Lists, tuples and arrays of floats and ints are taken; numpy arrays of any real dtype too.
    assert caliber.Pose([1, 2.5, 3]).translation == [1.0, 2.5, 3.0]
    assert caliber.Pose(np.array([1, 2, 3], dtype=np.int16), np.array([1, 0, 0, 0], dtype=np.float32)).translation == [1, 2, 3]
    # Numbers with __float__ (numpy scalars, Decimal, Fraction) and a column of a matrix, as before.
    from decimal import Decimal
    from fractions import Fraction
    assert caliber.Pose([np.float32(0.5), Decimal("1.5"), Fraction(1, 4)]).translation == [0.5, 1.5, 0.25]
    m = caliber.Pose((1.0, 2.0, 3.0)).matrix()
    assert caliber.Pose(m[:3, 3:]).translation == [1.0, 2.0, 3.0]
    complex_matrix = np.eye(4, dtype=complex)
    complex_matrix[0, 3] = 5j  # its imaginary part was dropped: a translation of 0
    for call, match in [
        (lambda: caliber.Pose(np.array([1, 2, 3 + 1j])), "translation: must be 3 real numbers, not dtype complex128"),
        (lambda: caliber.Pose([1, 2, 3j]), "translation: must be 3 real numbers"),
        (lambda: caliber.Pose((0, 0, 0), [True, False, False, False]), "quaternion: must be 4 real numbers, not a bool"),
        (lambda: caliber.Pose([True, 0, 0]), "translation: must be 3 real numbers, not a bool"),
        (lambda: caliber.Pose(np.array([True] * 3)), "translation: must be 3 real numbers, not dtype bool"),
        (lambda: caliber.Pose(["1", "2", "3"]), "translation: must be 3 real numbers"),
        (lambda: caliber.Pose((1, 2)), "translation: must be 3 real numbers, not 2 items"),
        (lambda: caliber.Pose(np.zeros((2, 2))), "translation: must be 3 real numbers, not an array of 4"),
        (lambda: caliber.Pose.from_quaternion((1, 0, 0), "wxyz"), "quaternion: must be 4 real numbers, not 3 items"),
        (lambda: caliber.Pose.from_matrix(complex_matrix), "matrix: must hold real numbers, not dtype complex128"),
        (lambda: caliber.Pose.from_matrix(np.eye(4, dtype=bool)), "matrix: must hold real numbers, not dtype bool"),
        (lambda: caliber.Pose.from_matrix(np.eye(4).astype(str)), "matrix: must hold real numbers"),
    ]:
        with pytest.raises(caliber.Error, match=match):
            call()


def test_engine_step_max_pairs_bounds_each_pair():
    models = [caliber.Model.load(TETRA), caliber.Model.load(FAN)]
    poses = [caliber.Pose(), pose(POSE)]
    engine = caliber.Engine()
    full = engine.step(models, poses, [(0, 1)], kind="proximity", tolerance=0.3)
    one = engine.step(models, poses, [(0, 1)], kind="proximity", tolerance=0.3, max_pairs=1)
    assert len(full) > 1 and not full.limit_reached
    assert len(one) == 1 and one.limit_reached


def test_broad_phase_gives_the_pairs_a_step_takes():
    models = [caliber.Model.load(TETRA), caliber.Model.load(FAN), caliber.Model.load(TETRA)]
    poses = [caliber.Pose(), pose(POSE), caliber.Pose((50.0, 0.0, 0.0))]
    pairs = caliber.broad_phase(models, poses, reach=0.3)
    assert pairs == [(0, 1)]
    assert caliber.broad_phase(models, poses, 0.3, fixed=[True, True, False]) == []
    assert caliber.broad_phase(models, poses, 0.3, fixed=np.array([True, True, False])) == []
    assert caliber.broad_phase(models, poses, 0.3, fixed=[1, 1, 0]) == []
    assert caliber.broad_phase(models, poses, 0.3, fixed=np.array([1, 1, 0])) == []
    # Flags are True or False (or 0 and 1), not any object's truth value.
    for flags, match in [([0.5, 1.0, 0.0], r"fixed\[0\]: must be True or False, not float"),
                         ([None] * 3, r"fixed\[0\]: must be True or False, not NoneType"),
                         ([True, 2, False], r"fixed\[1\]: must be True or False, not int"), ("yes", "fixed: must be a list")]:
        with pytest.raises(caliber.Error, match=match):
            caliber.broad_phase(models, poses, 0.3, fixed=flags)
        with pytest.raises(caliber.Error, match=match):
            caliber.Engine().find_pairs(models, poses, kind="proximity", tolerance=0.3, fixed=flags)
        with pytest.raises(caliber.Error, match=match):
            caliber.Engine().sweep(models, poses, poses, fixed=flags)
    assert caliber.broad_phase(models, poses, 0.3, ignored=[(0, 1)]) == []
    got = caliber.Engine().step(models, poses, pairs, kind="proximity", tolerance=0.3)
    want = caliber.query(models[0], poses[0], models[1], poses[1], kind="proximity", tolerance=0.3)
    assert got.pairs.tolist() == want.pairs.tolist() and len(got) > 0
    with pytest.raises(caliber.Error, match="broad phase: 3 models but 2 poses"):
        caliber.broad_phase(models, poses[:2])


def test_engine_find_pairs_keeps_its_tree_and_finds_the_broad_phase_pairs():
    rng = np.random.default_rng(7)
    models = [caliber.Model.load(TETRA) for _ in range(40)]
    engine = caliber.Engine(threads=2)
    for k in range(4):  # the same objects drifting: the engine refits its tree
        poses = [caliber.Pose(tuple(rng.uniform(0.0, 3.0, 3))) for _ in models]
        for kind, tolerance, reach in [("interference", None, 0.0), ("proximity", 0.25, 0.25)]:
            got = engine.find_pairs(models, poses, kind=kind, tolerance=tolerance)
            assert got == caliber.broad_phase(models, poses, reach), (k, kind)
            assert len(got) > 0
    fixed = [i % 2 == 0 for i in range(len(models))]
    assert engine.find_pairs(models, poses, fixed=fixed) == caliber.broad_phase(models, poses, 0.0, fixed=fixed)
    some = caliber.broad_phase(models, poses)[:3]
    assert engine.find_pairs(models, poses, ignored=some) == caliber.broad_phase(models, poses, ignored=some)
    with pytest.raises(caliber.Error, match="^tolerance: a distance query without one reaches every pair"):
        engine.find_pairs(models, poses, kind="distance")  # an unbounded distance names its pairs
    for reach in (1e300, 1e15 * (1 + 2**-52), float("inf"), float("nan"), -1.0):
        with pytest.raises(caliber.Error, match=r"^reach: must be finite, >= 0 and at most 1e15"):
            caliber.broad_phase(models, poses, reach)
    assert caliber.broad_phase(models, poses, 1e15) == [(a, b) for a in range(len(models)) for b in range(a + 1, len(models))]
    with pytest.raises(caliber.Error, match="3 models but 2 poses"):
        engine.find_pairs(models[:3], poses[:2])


def test_pickled_models_answer_the_same():
    a = caliber.Model.load(FAN)
    b = pickle.loads(pickle.dumps(a))
    assert b.triangles == a.triangles and b.height == a.height
    r1 = caliber.query(a, caliber.Pose(), a, pose(POSE), kind="contact", tolerance=0.3)
    r2 = caliber.query(b, caliber.Pose(), b, pose(POSE), kind="contact", tolerance=0.3)
    assert r1.pairs.tolist() == r2.pairs.tolist() and np.array_equal(r1.normals, r2.normals)


@pytest.mark.parametrize("method", ["sequential", "exploitation", "stealing", "aposteriori", "apriori", "hybrid"])
def test_engine_frames_give_the_query_answer(method):
    models = [caliber.Model.load(TETRA), caliber.Model.load(FAN), caliber.Model.load(TETRA)]
    engine = caliber.Engine(method, threads=2)
    for k in range(4):
        poses = [caliber.Pose(), pose(POSE), caliber.Pose((0.1 * k, 0.5, 0.0))]
        got = engine.step(models, poses, [(0, 1), (0, 2), (1, 2)], kind="proximity", tolerance=0.3)
        rows = []
        for a, b in [(0, 1), (0, 2), (1, 2)]:
            r = caliber.query(models[a], poses[a], models[b], poses[b], kind="proximity", tolerance=0.3)
            rows += [[a, b] + p for p in r.pairs.tolist()]
        assert got.objects.tolist() and [o + p for o, p in zip(got.objects.tolist(), got.pairs.tolist())] == rows


def test_a_scene_steps_through_the_engine():
    world = caliber.World(os.path.join(DATA, "scenes", "tetras.json"))
    assert world.objects == ["fixed", "mover"] and world.steps == 12
    engine = caliber.Engine("hybrid", threads=2)
    seq = caliber.Engine("sequential")
    for k in range(world.steps):
        a, b = world.step(engine, k), world.step(seq, k)
        assert a.pairs.tolist() == b.pairs.tolist() and np.array_equal(a.distances, b.distances)


def test_a_scene_is_swept_with_its_groups_and_turns(tmp_path):
    # A tetrahedron spinning 229 degrees a step past another at 90 degrees: found by its own turn,
    # not the shorter arc; in groups that may not touch, not found.
    def world(groups):
        scene = tmp_path / f"spin{len(groups)}.json"
        scene.write_text(json.dumps(dict({
            "dt": 0.01,
            "objects": [{"name": "spinner", "mesh": TETRA, "group": 1, "position": [0, 0, 0],
                         "motion": {"type": "velocity", "angular": [0, 0, 400]}},
                        {"name": "other", "mesh": TETRA, "group": 2, "position": [-1.6, 0.1, 0]}]}, **groups)))
        return caliber.World(scene)

    found = world({}).sweep(caliber.Engine(), 0)
    assert [pair for pair, _ in found] == [(0, 1)]
    assert found[0][1].status == "contact" and 0.0 < found[0][1].time < 0.5
    assert world({"groups": {"compatible": [[1, 1], [2, 2]]}}).sweep(caliber.Engine(), 0) == []
    with pytest.raises(caliber.Error, match="tolerance"):
        world({}).sweep(caliber.Engine(), 0, tolerance=-1.0)


def test_a_scene_step_cut_by_max_pairs_says_so(tmp_path):
    def world(query):
        scene = tmp_path / f"cut{len(query)}.json"
        scene.write_text(json.dumps({
            "steps": 3, "dt": 0.1, "query": query,
            "objects": [{"name": "fixed", "mesh": TETRA, "refine": 2},
                        {"name": "mover", "mesh": TETRA, "refine": 2, "position": [0.2, 0.1, 0.1],
                         "motion": {"type": "velocity", "linear": [-0.1, 0, 0]}}]}))
        return caliber.World(scene)

    full = world({"kind": "proximity", "tolerance": 0.05}).step(caliber.Engine(), 0)
    cut = world({"kind": "proximity", "tolerance": 0.05, "max_pairs": 1}).step(caliber.Engine(), 0)
    assert len(full) > 1 and not full.limit_reached
    assert len(cut) == 1 and cut.limit_reached


def test_bad_input_is_a_caliber_error_naming_the_file():
    with pytest.raises(caliber.Error, match="nope.off: no such file"):
        caliber.Model.load(os.path.join(DATA, "nope.off"))
    with pytest.raises(caliber.Error, match="unknown query kind"):
        caliber.query(caliber.Model.load(TETRA), caliber.Pose(), caliber.Model.load(TETRA), caliber.Pose(), kind="touch")
    with pytest.raises(caliber.Error, match="frame"):
        caliber.Engine("sequential").step([caliber.Model.load(TETRA)], [caliber.Pose()], [(0, 1)])


def test_threads_query_at_once_with_the_same_answers():
    a = caliber.Model.load(FAN)
    want = caliber.query(a, caliber.Pose(), a, pose(POSE), kind="contact", tolerance=0.3).pairs.tolist()
    got = [None] * 4

    def run(i):
        got[i] = caliber.query(a, caliber.Pose(), a, pose(POSE), kind="contact", tolerance=0.3).pairs.tolist()

    threads = [threading.Thread(target=run, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert got == [want] * 4


def test_kept_oriented_boxes_give_the_same_distance_and_survive_pickling():
    mesh = caliber.Mesh.load(FAN)
    plain, kept = caliber.Model(mesh), caliber.Model(mesh, oriented_boxes=True)
    assert not plain.oriented_boxes and kept.oriented_boxes
    assert pickle.loads(pickle.dumps(kept)).oriented_boxes
    assert caliber.Model.load(FAN, oriented_boxes=True).oriented_boxes and not caliber.Model.load(FAN).oriented_boxes
    near = caliber.Pose((0.1, 0.2, 1.5), (1.0, 0.0, 0.0, 0.0))
    r1 = caliber.query(plain, caliber.Pose(), plain, near, kind="distance")
    r2 = caliber.query(kept, caliber.Pose(), kept, near, kind="distance")
    assert len(r1) == 1 and r1.pairs.tolist() == r2.pairs.tolist() and r1.distances[0] == r2.distances[0]
    assert np.array_equal(r1.points_a, r2.points_a) and np.array_equal(r1.points_b, r2.points_b)
    assert r1.node_tests == r2.node_tests


def test_distance_without_a_tolerance_takes_any_distance():
    a = caliber.Model.load(TETRA)
    far = caliber.Pose((3.0, 0.5, 0.0), (1.0, 0.0, 0.0, 0.0))
    r = caliber.query(a, caliber.Pose(), a, far, kind="distance")
    assert len(r) == 1 and 2.0 < r.distances[0] < 4.0
    assert len(caliber.query(a, caliber.Pose(), a, far, kind="distance", tolerance=1.0)) == 0
    with pytest.raises(caliber.Error):
        caliber.query(a, caliber.Pose(), a, far, kind="proximity", tolerance=float("inf"))


def uv_sphere(radius, rings, segments):
    """A closed UV sphere as (vertices, faces) arrays."""
    verts = [(0.0, 0.0, radius)]
    for i in range(1, rings):
        t = np.pi * i / rings
        for j in range(segments):
            p = 2 * np.pi * j / segments
            verts.append((radius * np.sin(t) * np.cos(p), radius * np.sin(t) * np.sin(p), radius * np.cos(t)))
    verts.append((0.0, 0.0, -radius))
    faces = []
    ring = lambda i, j: 1 + (i - 1) * segments + j % segments
    for j in range(segments):
        faces.append((0, ring(1, j), ring(1, j + 1)))
    for i in range(1, rings - 1):
        for j in range(segments):
            faces += [(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)), (ring(i, j), ring(i + 1, j + 1), ring(i, j + 1))]
    last = len(verts) - 1
    for j in range(segments):
        faces.append((ring(rings - 1, j + 1), ring(rings - 1, j), last))
    return np.array(verts), np.array(faces)


def test_a_second_step_on_a_busy_engine_is_an_error_not_a_crash():
    ball = caliber.Model(caliber.Mesh(*uv_sphere(1.0, 120, 160)))
    models, heavy = [ball, ball], [caliber.Pose(), caliber.Pose((1.9, 0.0, 0.0))]
    far = [caliber.Pose(), caliber.Pose((9.0, 0.0, 0.0))]
    alone = caliber.Engine(threads=2).step(models, heavy, [(0, 1)], kind="proximity", tolerance=0.2)
    assert len(alone) > 0
    engine = caliber.Engine(threads=2)
    done, got, refused = threading.Event(), [], []

    def worker():
        while True:
            try:
                got.append(engine.step(models, heavy, [(0, 1)], kind="proximity", tolerance=0.2))
                break
            except caliber.Error:  # the main thread held the engine first
                pass
        done.set()

    thread = threading.Thread(target=worker)
    thread.start()
    while not done.is_set():
        try:
            engine.step(models, far, [(0, 1)], kind="proximity", tolerance=0.2)
        except caliber.Error as e:
            assert "another call on the same engine is running" in str(e)
            refused.append(e)
    thread.join()
    assert refused, "the heavy step never overlapped a second call"
    assert got[0].pairs.tolist() == alone.pairs.tolist() and np.array_equal(got[0].points_a, alone.points_a)


def test_mesh_refuses_faces_that_are_not_integers_and_vertices_that_are_not_real():
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    assert len(caliber.Mesh(v, np.array([[0, 1, 2]], dtype=np.int32))) == 1
    assert len(caliber.Mesh(v.astype(np.float32), np.array([[0, 1, 2]], dtype=np.uint16))) == 1
    assert len(caliber.Mesh(v.astype(np.int64), [[0, 1, 2]])) == 1  # integer coordinates are real numbers
    with pytest.raises(caliber.Error, match="faces: must hold integer vertex indices, not dtype float64"):
        caliber.Mesh(v, np.array([[0.9, 1.0, 2.0]]))  # would have become vertex 0
    with pytest.raises(caliber.Error, match="faces: must hold integer vertex indices, not dtype bool"):
        caliber.Mesh(v, np.array([[True, False, True]]))
    with pytest.raises(caliber.Error, match="vertices: must hold real numbers, not dtype complex128"):
        caliber.Mesh(v.astype(complex), np.array([[0, 1, 2]]))
    with pytest.raises(caliber.Error, match="vertices: must hold real numbers, not dtype bool"):
        caliber.Mesh(v.astype(bool), np.array([[0, 1, 2]]))


# A pickle that creates a Model (NEWOBJ) and never gives it its state (no BUILD): 17 bytes.
MODEL_WITHOUT_STATE = b"\x80\x02ccaliber\nModel\nq\x00)\x81q\x01."


def test_objects_made_without_their_state_refuse_every_use():
    good = caliber.Model.load(TETRA)
    husk = caliber.Model.__new__(caliber.Model)
    for use in (lambda: husk.triangles, lambda: husk.mesh, lambda: pickle.dumps(husk),
                lambda: caliber.query(husk, caliber.Pose(), good, caliber.Pose()),
                lambda: caliber.query(good, caliber.Pose(), pickle.loads(MODEL_WITHOUT_STATE), caliber.Pose()),
                lambda: caliber.Engine().step([good, husk], [caliber.Pose()] * 2, [(0, 1)]),
                lambda: caliber.broad_phase([good, husk], [caliber.Pose()] * 2)):
        with pytest.raises(caliber.Error, match="Model: was never built"):
            use()
    engine = caliber.Engine.__new__(caliber.Engine)
    with pytest.raises(caliber.Error, match="Engine: was never built"):
        engine.step([good, good], [caliber.Pose()] * 2, [(0, 1)])
    with pytest.raises(caliber.Error, match="World: was never built"):
        caliber.World.__new__(caliber.World).steps
    with pytest.raises(caliber.Error, match="Pose: was never built"):
        caliber.query(good, caliber.Pose.__new__(caliber.Pose), good, caliber.Pose())
    with pytest.raises(caliber.Error, match="Mesh: was never built"):
        caliber.Model(caliber.Mesh.__new__(caliber.Mesh))
    with pytest.raises(caliber.Error, match="Result: was never built"):
        len(caliber.Result.__new__(caliber.Result))
    for field in ("status", "time", "queries", "pair", "points", "distance"):
        with pytest.raises(caliber.Error, match="Sweep: was never built"):
            getattr(caliber.Sweep.__new__(caliber.Sweep), field)
    # The husk's state can still be given once, as unpickling does; then it is an ordinary model.
    husk.__setstate__(good.__getstate__())
    assert husk.triangles == good.triangles


def test_built_objects_are_not_built_again():
    model = caliber.Model.load(TETRA)
    with pytest.raises(caliber.Error, match="Model: is already built: __setstate__ runs once"):
        model.__setstate__(caliber.Model.load(FAN).__getstate__())
    with pytest.raises(caliber.Error, match="Model: is already built: __init__ runs once"):
        model.__init__(caliber.Mesh.load(FAN))
    assert model.triangles == caliber.Model.load(TETRA).triangles
    engine = caliber.Engine("sequential", 1)
    with pytest.raises(caliber.Error, match="Engine: is already built"):
        engine.__init__("stealing", 2)
    assert engine.threads == 1


def test_tampered_model_states_are_caliber_errors():
    v, f, adjacency, boxes = caliber.Model.load(TETRA).__getstate__()
    states = {
        "expected a tuple, got int": 5,
        "expected 3 or 4 items, got 2": (v, f),
        "item 2 must be True or False": (v, f, "yes"),
        "item 3 must be True or False": (v, f, True, 1),
        "vertices: must hold real numbers, not dtype <U1": (np.array([["a", "b", "c"]]), f, True),
        "vertices: must be an n x 3 array": (v[:, :2], f, True),
        "vertices: must hold real numbers, not dtype object": (np.array([[None, 1, 2]]), f, True),
        "faces: must hold integer vertex indices, not dtype float64": (v, f.astype(float), True),
        "faces: must be an m x 3 array": (v, np.zeros((2, 2, 2), dtype=int), True),
        "refers to vertex 99": (v, np.array([[0, 1, 99]]), True),
        "refers to vertex -1": (v, np.array([[0, 1, -1]]), True),
        "refers to vertex 18446744073709551615": (v, np.array([[0, 1, 2**64 - 1]], dtype=np.uint64), True),
        "non-finite": (np.where(v == v.max(), np.nan, v), f, True),
    }
    for message, state in states.items():
        husk = caliber.Model.__new__(caliber.Model)
        with pytest.raises(caliber.Error, match="pickle: not a caliber.Model state: .*" + message.replace("(", r"\(")):
            husk.__setstate__(state)
        with pytest.raises(caliber.Error, match="Model: was never built"):
            husk.triangles  # a refused state leaves the object unusable, not half-built


def test_paths_that_are_not_utf8_are_named_escaped(tmp_path):
    raw = os.fsencode(tmp_path) + b"/caf\xe9\nname.obj"
    with open(raw, "wb") as f:
        f.write(b"v 1\xff\x00 0 0\n")
    for path in (raw, os.fsdecode(raw)):  # bytes, or str with the byte as a surrogate escape
        with pytest.raises(caliber.Error) as error:
            caliber.Mesh.load(path)
        assert str(error.value).endswith("/caf\\xe9\\x0aname.obj: cannot parse mesh: line 1: '1\\xff\\x00' is not a number")
    with pytest.raises(caliber.Error, match="path: must be a str, bytes or os.PathLike, not int"):
        caliber.Model.load(5)
    # A NUL byte would end the C string the file is opened by: another file (tetra.off) was read.
    for load in (caliber.Mesh.load, caliber.Model.load, caliber.World):
        with pytest.raises(caliber.Error, match="path: holds a NUL byte"):
            load(TETRA + "\0.bogus")
    assert caliber.Model.load(pathlib.Path(TETRA)).triangles == 4


def test_every_protocol_pickles_meshes_models_and_poses_and_refuses_the_rest():
    model, p = caliber.Model.load(FAN, oriented_boxes=True), caliber.Pose([1, 2, 3], [0.3, 0.1, 0.2, 0.9])
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        again = pickle.loads(pickle.dumps(model, protocol))
        assert again.triangles == model.triangles and again.oriented_boxes
        assert np.array_equal(again.mesh.vertices, model.mesh.vertices)
        assert pickle.loads(pickle.dumps(p, protocol)).quaternion == p.quaternion
        assert np.array_equal(pickle.loads(pickle.dumps(model.mesh, protocol)).faces, model.mesh.faces)
        for thing, name in ((caliber.Engine(), "Engine"), (caliber.World(os.path.join(DATA, "scenes", "tetras.json")), "World")):
            with pytest.raises(caliber.Error, match=name + ": cannot be pickled"):
                pickle.dumps(thing, protocol)


def box_model(hx, hy, hz):
    corners = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return caliber.Model(caliber.Mesh(corners, faces))


def test_sweep_catches_a_needle_that_tunnels_through_a_plate():
    plate, needle = box_model(1.0, 1.0, 0.001), box_model(0.001, 0.001, 0.1)
    start, end = caliber.Pose((0.3, 0.2, 1.0), (1, 0, 0, 0)), caliber.Pose((0.3, 0.2, -1.0), (1, 0, 0, 0))
    for p in (start, end):
        assert len(caliber.query(plate, caliber.Pose(), needle, p, max_pairs=1)) == 0
    s = caliber.sweep(plate, caliber.Pose(), caliber.Pose(), needle, start, end, tolerance=1e-6)
    assert s.status == "contact"
    first = (1.0 - 0.101) / 2.0  # the tip (z - 0.1) reaches the plate's top (0.001)
    assert first - 1e-6 <= s.time <= first
    assert s.distance <= 1e-6 and s.pair is not None and len(s.points) == 2
    apart = caliber.sweep(plate, caliber.Pose(), caliber.Pose(), needle, start, caliber.Pose((3.0, 0.2, 1.0), (1, 0, 0, 0)))
    assert (apart.status, apart.time, apart.pair, apart.distance) == ("free", 1.0, None, None)
    with pytest.raises(caliber.Error, match="tolerance"):
        caliber.sweep(plate, caliber.Pose(), caliber.Pose(), needle, start, end, tolerance=-1.0)
    with pytest.raises(caliber.Error):
        pickle.dumps(s)


def test_engine_sweep_equals_sweep_on_every_pair():
    plate, needle = box_model(1.0, 1.0, 0.001), box_model(0.001, 0.001, 0.1)
    models = [plate, needle, needle, plate]
    start = [caliber.Pose(), caliber.Pose((0.3, 0.2, 1.0), (1, 0, 0, 0)), caliber.Pose((5.0, 0, 1.0), (1, 0, 0, 0)),
             caliber.Pose((9.0, 0, 0), (1, 0, 0, 0))]
    end = [caliber.Pose(), caliber.Pose((0.3, 0.2, -1.0), (1, 0, 0, 0)), caliber.Pose((5.0, 0, 2.0), (1, 0, 0, 0)),
           caliber.Pose((9.0, 0, 0), (1, 0, 0, 0))]
    got = caliber.Engine(threads=2).sweep(models, start, end, tolerance=1e-6)
    assert [pair for pair, _ in got] == [(0, 1)]  # the needle through the plate; the other needle flies off alone
    want = caliber.sweep(plate, start[0], end[0], needle, start[1], end[1], tolerance=1e-6)
    (pair, s), = got
    assert (s.status, s.time, s.pair) == (want.status, want.time, want.pair)
    assert caliber.Engine().sweep(models, start, end, ignored=[(0, 1)]) == []
    with pytest.raises(caliber.Error, match="end pose"):
        caliber.Engine().sweep(models, start, end[:3])


def random_passes(n, seed):
    """n motions of B from one side of A to the other, as N x 7 rows (translation, quaternion wxyz)."""
    rng = np.random.default_rng(seed)
    side = rng.normal(size=(n, 3))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    turn = rng.normal(size=(n, 4))
    turn /= np.linalg.norm(turn, axis=1, keepdims=True)
    off = rng.uniform(-1.5, 1.5, size=(n, 3))  # through A's middle, or beside it
    start = np.hstack([2.5 * side + off, turn])
    end = np.hstack([-2.5 * side + off, np.tile([1.0, 0, 0, 0], (n, 1))])
    return start, end


@pytest.mark.parametrize("method,threads", [("sequential", 1), ("stealing", 2), ("hybrid", 2), ("exploitation", 3)])
def test_sweep_many_equals_sweep_row_for_row(method, threads):
    slab = box_model(1.0, 1.0, 0.05)  # a thin slab the needles fly through or past
    needle = box_model(0.01, 0.01, 0.6)
    start, end = random_passes(30, 5)
    engine = caliber.Engine(method, threads=threads)
    got = engine.sweep_many(slab, caliber.Pose(), caliber.Pose(), needle, start, end, tolerance=1e-6)
    assert len(got) == 30 and got.time.shape == (30,) and got.pairs.shape == (30, 2) and got.points_a.shape == (30, 3)
    assert got.contact.sum() > 5 and (~got.contact).sum() > 0, "the motions should both meet and miss"
    for i in range(30):
        s = caliber.sweep(slab, caliber.Pose(), caliber.Pose(), needle, caliber.Pose(start[i, :3], start[i, 3:]),
                          caliber.Pose(end[i, :3], end[i, 3:]), tolerance=1e-6)
        assert got.time[i] == s.time and got.queries[i] == s.queries
        assert bool(got.contact[i]) == (s.status == "contact") and bool(got.undecided[i]) == (s.status == "undecided")
        if s.status == "contact":
            assert tuple(got.pairs[i]) == s.pair and got.distance[i] == s.distance
            assert (tuple(got.points_a[i]), tuple(got.points_b[i])) == s.points
        else:
            assert tuple(got.pairs[i]) == (-1, -1) and got.distance[i] == np.inf and np.isnan(got.points_a[i]).all()
    # The module function, scipy's quaternion order, and 4 x 4 matrices give the same rows.
    xyzw = lambda rows: np.hstack([rows[:, :3], rows[:, 4:], rows[:, 3:4]])
    again = caliber.sweep_many(slab, caliber.Pose(), caliber.Pose(), needle, xyzw(start), xyzw(end), tolerance=1e-6,
                               order="xyzw", threads=threads)
    assert (again.time == got.time).all() and (again.pairs == got.pairs).all()
    matrices = np.array([caliber.Pose(r[:3], r[3:]).matrix() for r in start])
    m = caliber.sweep_many(slab, caliber.Pose(), caliber.Pose(), needle, matrices, end, tolerance=1e-6)
    assert (m.contact == got.contact).all()


def test_sweep_many_refuses_bad_motions():
    plate, needle = box_model(1.0, 1.0, 0.001), box_model(0.001, 0.001, 0.1)
    start, end = random_passes(4, 1)
    with pytest.raises(caliber.Error, match="end_b: 3 poses but start_b has 4"):
        caliber.sweep_many(plate, caliber.Pose(), caliber.Pose(), needle, start, end[:3])
    with pytest.raises(caliber.Error, match="start_b: 4 motions but start_a gives 2"):
        caliber.sweep_many(plate, [caliber.Pose()] * 2, [caliber.Pose()] * 2, needle, start, end)
    bad = end.copy()
    bad[2, 0] = np.nan
    with pytest.raises(caliber.Error, match=r"end_b\[2\]"):
        caliber.sweep_many(plate, caliber.Pose(), caliber.Pose(), needle, start, bad)
    with pytest.raises(caliber.Error, match="max_queries"):
        caliber.sweep_many(plate, caliber.Pose(), caliber.Pose(), needle, start, end, max_queries=0)
    got = caliber.sweep_many(plate, caliber.Pose(), caliber.Pose(), needle, start, end)
    with pytest.raises(caliber.Error, match="Sweeps"):
        pickle.dumps(got)
    with pytest.raises(caliber.Error):
        caliber.Sweeps.__new__(caliber.Sweeps).time
    # Its arrays are read-only views: the Sweeps keeps its rows whatever is done to them.
    before = {name: getattr(got, name).tobytes() for name in ("contact", "undecided", "time", "pairs", "distance", "points_a",
                                                               "points_b", "queries")}
    for name in before:
        view = getattr(got, name)
        with pytest.raises(ValueError, match="read-only"):
            view[...] = 0
        view.shape = (-1,)
    assert len(got) == 4 and all(getattr(got, name).tobytes() == b for name, b in before.items())
