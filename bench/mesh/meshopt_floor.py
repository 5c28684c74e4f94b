"""What the simplification benchmarks share (bench/mesh/run_meshopt_error.py,
bench/blender/bench_simplify.py, bench/mesh/coarse_floor.py): meshoptimizer's meshopt_simplify through
ctypes (Debian's libmeshoptimizer-dev, a benchmark dependency only), and
points over triangles on a barycentric lattice, each triangle's points
together (mesh order, so an evaluation of them keeps its locality)."""
import ctypes
import ctypes.util
import time

import numpy as np


def load():
    """meshoptimizer with the signatures used here, or None when it is not installed."""
    so = ctypes.util.find_library("meshoptimizer")
    if not so:
        return None
    lib = ctypes.CDLL(so)
    lib.meshopt_simplify.restype = ctypes.c_size_t
    lib.meshopt_simplify.argtypes = (
        ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t,
        ctypes.c_size_t, ctypes.c_size_t, ctypes.c_float, ctypes.c_uint,
        ctypes.POINTER(ctypes.c_float))
    lib.meshopt_simplifyScale.restype = ctypes.c_float
    lib.meshopt_simplifyScale.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)
    return lib


def best_ms(f, rounds=1):
    """(the best of rounds calls of f in milliseconds, the last call's result)"""
    best, out = float("inf"), None
    for _ in range(rounds):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return 1000 * best, out


def simplify(lib, positions, triangles, error, rounds=1):
    """meshopt_simplify of triangles (n, 3) over positions (m, 3) down to
    error (in the positions' units, meshoptimizer's own quadric error), as
    far as that allows: (triangles (k, 3), meshoptimizer's error in those
    units, the best of rounds calls in milliseconds)."""
    pos = np.ascontiguousarray(positions, dtype=np.float32)
    idx = np.ascontiguousarray(triangles, dtype=np.uint32)
    scale = lib.meshopt_simplifyScale(pos.ctypes.data, len(pos), 12)
    dst = np.empty_like(idx)
    own = ctypes.c_float()
    ms, n = best_ms(lambda: lib.meshopt_simplify(dst.ctypes.data, idx.ctypes.data, idx.size,
                                                 pos.ctypes.data, len(pos), 12, 0,
                                                 error / scale, 0, ctypes.byref(own)), rounds)
    return dst.ravel()[:n].reshape(-1, 3).astype(np.int64), own.value * scale, ms


def lattice(V, F, step, corners=True, index=False):
    """Points over every triangle F (n, 3) of V: n steps along each edge, n
    its longest edge over step rounded up (at least 1); without corners,
    the triangle's three corners left out (as the simplifier samples).
    With index, also the triangle of each point."""
    Q = V[np.asarray(F, dtype=np.int64)]
    k = np.ceil(np.linalg.norm(Q[:, [1, 2, 0]] - Q, axis=2).max(1) / step).clip(1)
    pts, tri = [np.zeros((0, 3))], [np.zeros(0, np.int64)]
    for n in np.unique(k).astype(int):
        w = np.array([(i, j, n - i - j) for i in range(n + 1) for j in range(n + 1 - i)
                      if corners or not (i + j == 0 or i == n or j == n)], float) / n
        if len(w):
            sel = np.nonzero(k == n)[0]
            pts.append(np.einsum("pk,tkd->tpd", w, Q[sel]).reshape(-1, 3))
            tri.append(np.repeat(sel, len(w)))
    return (np.concatenate(pts), np.concatenate(tri)) if index else np.concatenate(pts)
