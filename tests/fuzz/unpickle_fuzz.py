#!/usr/bin/env python3
"""Fuzzes the Python module's unpickler: pickles of caliber.Model, mutated byte by byte and state by
state, are loaded and every loaded object is used (its mesh, a query, a step, pickling it again).
Every use must answer or raise caliber.Error; a crash (a signal), a hang or any other exception
from caliber is a finding, saved to --findings as the input's bytes.

Loading goes through an Unpickler that resolves caliber's and numpy's names only, as a careful
program loading pickles would, so a mutated name never calls into anything else.

  unpickle_fuzz.py --seconds 600        the long run
  unpickle_fuzz.py --iterations 3000    the short run ctest makes (fixed seed)

A crash is caliber's only when the input, loaded with every caliber name stubbed out, does not
crash the same way: numpy's own __setstate__ crashes on some mutated array states. Those inputs are
kept as outside-caliber-* and the run goes on.
"""
import argparse
import io
import os
import pickle
import random
import resource
import subprocess
import sys
import time

import numpy as np

import caliber

ALLOWED = {("caliber", "_model_from_state"), ("caliber", "_pose_from_state"), ("caliber", "Model"), ("caliber", "Pose"), ("caliber", "Mesh"), ("caliber", "Engine"), ("caliber", "World"),
           ("caliber", "Result"), ("numpy", "ndarray"), ("numpy", "dtype"), ("numpy.core.multiarray", "_reconstruct"),
           ("numpy.core.multiarray", "scalar"), ("numpy.core.numeric", "_frombuffer"), ("copyreg", "_reconstructor"), ("builtins", "object")}


class Restricted(pickle.Unpickler):
    def find_class(self, module, name):
        if (module, name) not in ALLOWED:
            raise pickle.UnpicklingError(f"{module}.{name} is not allowed")
        return super().find_class(module, name)


ENGINE = caliber.Engine("hybrid", 2)


def tetra():
    return caliber.Model(caliber.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                                      [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]))


def seeds():
    model, out = tetra(), []
    for protocol in range(0, pickle.HIGHEST_PROTOCOL + 1):
        out.append(pickle.dumps(model, protocol=protocol))
        out.append(pickle.dumps([model, model], protocol=protocol))
    out.append(b"\x80\x02ccaliber\nModel\nq\x00)\x81q\x01.")  # created, never given its state
    return out


def random_value(rng):
    """A value a tampered state might hold in place of an array or a flag."""
    kind = rng.randrange(9)
    shape = tuple(rng.randrange(0, 5) for _ in range(rng.randrange(0, 4)))
    if kind == 0:
        return rng.choice([None, True, False, 0, -1, 2**63, 1.5, float("nan"), "x", b"\xff", (), [], {}])
    if kind == 1:
        return np.random.default_rng(rng.randrange(2**32)).normal(size=shape)
    if kind == 2:
        return np.random.default_rng(rng.randrange(2**32)).integers(-5, 9, size=shape)
    if kind == 3:
        dtype = rng.choice([np.int8, np.uint64, np.float16, np.complex128, np.bool_, object, "U3", "S2", "V4"])
        return np.zeros(shape, dtype=dtype)
    if kind == 4:
        return np.full((rng.randrange(0, 6), 3), rng.choice([np.inf, -np.inf, np.nan, 1e308, -0.0, 5e-324]))
    if kind == 5:
        return np.array([[0, 1, rng.choice([4, -1, -5, 2**31, 2**32, 2**63 - 1, -(2**63)])]])
    if kind == 6:
        return np.zeros((4, 3))[:, ::2] if rng.random() < 0.5 else np.arange(12.0).reshape(4, 3).T
    if kind == 7:
        return tetra()
    return np.arange(12.0).reshape(4, 3)


def state_pickle(rng):
    """A pickle that gives a Model a tampered state (tuple items replaced, added or dropped)."""
    state = list(tetra().__getstate__())
    for _ in range(rng.randrange(1, 4)):
        op = rng.randrange(4)
        if op == 0 and len(state) > 0:
            state[rng.randrange(len(state))] = random_value(rng)
        elif op == 1:
            state.insert(rng.randrange(len(state) + 1), random_value(rng))
        elif op == 2 and len(state) > 0:
            del state[rng.randrange(len(state))]
    body = random_value(rng) if rng.random() < 0.1 else tuple(state)

    if rng.random() < 0.5:  # as caliber pickles a Model: caliber._model_from_state(state)
        class Tampered:
            def __reduce__(self):
                return (caliber._model_from_state, (body,))

        return pickle.dumps(Tampered(), protocol=rng.randrange(0, pickle.HIGHEST_PROTOCOL + 1))
    # As the default object protocol would: NEWOBJ caliber.Model, then BUILD (__setstate__) with it.
    return b"\x80\x02ccaliber\nModel\n)\x81" + pickle.dumps(body, protocol=2)[2:-1] + b"b."


def mutate(data, rng):
    data = bytearray(data)
    for _ in range(rng.randrange(1, 5)):
        op = rng.randrange(5)
        i = rng.randrange(len(data) + 1) if data else 0
        if op == 0 and data:
            data[min(i, len(data) - 1)] = rng.randrange(256)
        elif op == 1:
            data[i:i] = bytes([rng.randrange(256)])
        elif op == 2 and data:
            del data[i:i + rng.randrange(1, 9)]
        elif op == 3 and data:
            j = rng.randrange(len(data))
            data[i:i] = data[j:j + rng.randrange(1, 17)]
        else:
            data[i:i] = rng.choice([b"\x81", b".", b"b", b"R", b")", b"N", b"\x88", b"\x89", b"K\x05", b"t", b"}"])
    return bytes(data)


def use(obj, seen=None):
    """Uses every caliber object inside `obj`: each use answers or raises caliber.Error."""
    seen = seen if seen is not None else set()
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, (tuple, list)):
        for item in obj[:8]:
            use(item, seen)
    elif isinstance(obj, caliber.Model):
        for action in (lambda: (obj.triangles, obj.height, obj.mesh.vertices.sum(), obj.oriented_boxes),
                       lambda: caliber.query(obj, caliber.Pose(), obj, caliber.Pose([0.1, 0.2, 0.3]), kind="distance"),
                       lambda: caliber.query(obj, caliber.Pose(), tetra(), caliber.Pose(), kind="contact", tolerance=0.1),
                       lambda: ENGINE.step([obj, obj], [caliber.Pose()] * 2, [(0, 1)]),
                       lambda: pickle.loads(pickle.dumps(obj)).triangles):
            try:
                action()
            except caliber.Error:
                pass
    elif isinstance(obj, (caliber.Mesh, caliber.Pose, caliber.Engine, caliber.World, caliber.Result)):
        try:
            repr(obj), caliber.Model(obj) if isinstance(obj, caliber.Mesh) else None
        except caliber.Error:
            pass


def one(data):
    try:
        obj = Restricted(io.BytesIO(data)).load()
    except caliber.Error:
        return
    except Exception:  # the pickle itself is broken: pickle's errors are not caliber's to make
        return
    use(obj)


def worker(args):
    """Runs inputs in this process; the parent restarts it after a crash and saves the input."""
    # A mutated memo index (LONG_BINPUT 1268021601) makes pickle itself allocate gigabytes: bounded,
    # such an input fails fast with MemoryError, pickle's error and not caliber's. (Under ASan or
    # TSan, whose shadow memory is terabytes of address space, max_allocation_size_mb bounds it.)
    preloaded = os.environ.get("LD_PRELOAD", "")
    if "libasan" not in preloaded and "libtsan" not in preloaded:
        resource.setrlimit(resource.RLIMIT_AS, (6 << 30, 6 << 30))
    rng = random.Random(args.seed)
    corpus = seeds()
    deadline = time.monotonic() + args.seconds if args.seconds else None
    current = os.path.join(args.findings, f"current-{os.getpid()}")
    done = 0
    while (deadline is None and done < args.iterations) or (deadline is not None and time.monotonic() < deadline):
        data = state_pickle(rng) if rng.random() < 0.4 else mutate(rng.choice(corpus), rng)
        with open(current, "wb") as f:
            f.write(data)
        one(data)
        done += 1
    os.remove(current)
    print(f"unpickle_fuzz: {done} inputs, no finding")


class Stubbed(Restricted):
    """Loads with every caliber name replaced by a function that only records its arguments."""
    def find_class(self, module, name):
        if module == "caliber":
            return lambda *args: ("caliber", name, len(args))
        return super().find_class(module, name)


def triage(path):
    """Loads the input with caliber left out: exits by the same signal when the crash is not caliber's."""
    with open(path, "rb") as f:
        data = f.read()
    try:
        Stubbed(io.BytesIO(data)).load()
    except Exception:
        pass


def run_worker(args, seed, seconds, iterations):
    """One worker process; returns (exit code, stdout, stderr, the input it was on)."""
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", "--seconds", str(seconds), "--iterations",
           str(iterations), "--seed", str(seed), "--findings", args.findings]
    timeout = (seconds or iterations / 20) + 120
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        err += f"\nunpickle_fuzz: no answer after {timeout:.0f} s (a hang)\n"
    return proc.returncode, out, err, os.path.join(args.findings, f"current-{proc.pid}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=0.0)
    parser.add_argument("--iterations", type=int, default=3000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--findings", default=os.environ.get("TMPDIR", "/tmp"))
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--triage", help=argparse.SUPPRESS)
    parser.add_argument("replay", nargs="*", help="inputs to load and use, one after another (no fuzzing)")
    args = parser.parse_args()
    if args.triage:
        triage(args.triage)
        return 0
    if args.replay:
        for path in args.replay:
            with open(path, "rb") as f:
                one(f.read())
        print(f"unpickle_fuzz: {len(args.replay)} inputs replayed")
        return 0
    if args.worker:
        worker(args)
        return 0
    os.makedirs(args.findings, exist_ok=True)
    # A crash is caliber's only if the input, loaded with caliber left out, does not crash too: numpy
    # 1.24's dtype and ndarray __setstate__ crash on some mutated states by themselves. Those are
    # counted, kept aside and the fuzzing goes on with the next seed.
    deadline = time.monotonic() + args.seconds if args.seconds else None
    seed, outside = args.seed, 0
    while True:
        seconds = max(1.0, deadline - time.monotonic()) if deadline else 0.0
        code, out, err, current = run_worker(args, seed, seconds, args.iterations)
        sys.stdout.write(out)
        if code == 0:
            break
        crashed = code < 0 and os.path.exists(current)
        if crashed and subprocess.run([sys.executable, os.path.abspath(__file__), "--triage", current],
                                      capture_output=True).returncode == code:
            outside += 1
            os.replace(current, os.path.join(args.findings, f"outside-caliber-{seed}"))
            if deadline is None or time.monotonic() >= deadline:
                break
            seed += 1
            continue
        sys.stderr.write(err[-4000:])
        if os.path.exists(current):
            finding = os.path.join(args.findings, f"unpickle-finding-{seed}")
            os.replace(current, finding)
            print(f"unpickle_fuzz: finding (exit {code}) saved to {finding}", file=sys.stderr)
        return 1
    if outside:
        print(f"unpickle_fuzz: {outside} crash(es) outside caliber (the input crashes with caliber left out), "
              f"kept in {args.findings}/outside-caliber-*")
    return 0


if __name__ == "__main__":
    sys.exit(main())
