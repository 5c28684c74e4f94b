"""The floor of a coarse-first adaptive mesher (docs/meshing.md, Adaptive
simplification): what a mesher that meshes a grid twice as coarse, checks
it against the field and meshes the fine grid only where the check fails
would cost at least, and how many triangles it would leave. Used by
bench/blender/bench_simplify.py (the add-on's live update) and
bench/mesh/run_meshopt_error.py (the errors of sample points).

The model is kept in the adaptive mesher's favour everywhere:
- a coarse cell passes when every coarse triangle in it (by centroid) is
  within max(tolerance, the largest error of the fine triangles in the same
  cell): the fine mesh's own error is never held against it; fine
  triangles in a coarse cell with no coarse triangle count as skipped;
- it pays the uniform mesher at half the resolution, the field once at
  points a fine cell apart over every coarse triangle (corners left out:
  the coarse vertices are on the surface), and the fine meshing in
  proportion to the fine triangles left (its fixed costs scale down too);
- the seams between the two resolutions, their vertices and any repair
  for manifoldness cost nothing and add no triangle.
Errors are measured as in run_meshopt_error.py: points at most a quarter
cell apart over every triangle, moved onto the surface by Newton steps
along the gradient; the distance moved bounds a point's error from above.
"""
import numpy as np

import meshopt_floor


def sample_errors(ev, V, F, h, step=0.25, threads=0):
    """(errors in cells of h, triangle of each sample, samples not on the
    surface after 6 Newton steps): points at most step cells apart over
    every triangle F of V, each moved onto the surface; the distance moved
    is an upper bound on its error (those not reaching the surface get 0
    and are flagged)."""
    S, tri = meshopt_floor.lattice(V, F, step * h, index=True)
    X = S.copy()
    for _ in range(6):
        v, g = ev.eval(X, threads=threads)
        X = X - (v / np.maximum(np.einsum("ij,ij->i", g, g), 1e-300))[:, None] * g
    v, g = ev.eval(X, threads=threads)
    off = np.abs(v) / np.maximum(np.linalg.norm(g, axis=1), 1e-300) > 1e-3 * h
    d = np.where(off, 0.0, np.linalg.norm(X - S, axis=1) / h)
    return d, tri, off


def triangle_errors(ev, V, F, h, threads=0):
    """the largest sample error (cells) of each triangle"""
    d, tri, _off = sample_errors(ev, V, F, h, threads=threads)
    e = np.zeros(len(F))
    np.maximum.at(e, tri, d)
    return e


def _cells(m, origin, cell):
    """the coarse cell (one integer key) of each triangle's centroid; cell:
    the coarse grid's cell size per axis"""
    c = np.floor((m.positions[m.triangles.astype(np.int64)].mean(1) - origin) / cell)
    c = c.astype(np.int64)
    return (c[:, 0] * 1_000_003 + c[:, 1]) * 1_000_003 + c[:, 2]


def measure(ev, lo, hi, res, tolerances, threads=0, features=False, rounds=7):
    """The coarse-first floor at res cells over [lo, hi]. Returns a dict:
    fine_ms / coarse_ms (best of rounds, the uniform mesher at res and
    res / 2), check_ms (the field once at check_points, best of rounds),
    fine / coarse triangles, and for each tolerance (cells of the fine grid)
    skipped (the fraction of fine triangles in passing coarse cells) and
    triangles (coarse ones in passing cells plus fine ones elsewhere)."""
    h = max(b - a for a, b in zip(lo, hi)) / res
    kw = dict(threads=threads, features=features)
    fine = ev.mesh(lo, hi, resolution=res, **kw)
    coarse = ev.mesh(lo, hi, resolution=res // 2, **kw)
    pts = meshopt_floor.lattice(coarse.positions, coarse.triangles, h, corners=False)
    fine_ms = coarse_ms = check_ms = 1e30
    for _ in range(rounds):  # alternated, so the machine's load falls on all three
        fine_ms = min(fine_ms, meshopt_floor.best_ms(lambda: ev.mesh(lo, hi, resolution=res,
                                                                      **kw))[0])
        coarse_ms = min(coarse_ms, meshopt_floor.best_ms(
            lambda: ev.mesh(lo, hi, resolution=res // 2, **kw))[0])
        check_ms = min(check_ms, meshopt_floor.best_ms(lambda: ev.eval(pts, threads=threads))[0])
    ef = triangle_errors(ev, fine.positions, fine.triangles, h, threads)
    ec = triangle_errors(ev, coarse.positions, coarse.triangles, h, threads)
    origin = np.asarray(coarse.origin, float)
    cell = np.asarray(coarse.cell, float)
    kf = _cells(fine, origin, cell)
    kc = _cells(coarse, origin, cell)
    fine_err = {}
    for k, e in zip(kf.tolist(), ef.tolist()):
        fine_err[k] = max(fine_err.get(k, 0.0), e)
    r = {"fine_ms": fine_ms, "coarse_ms": coarse_ms, "check_ms": check_ms,
         "check_points": len(pts), "fine": len(fine.triangles), "coarse": len(coarse.triangles),
         "coarse_error_median": float(np.median(ec)), "tolerances": {}}
    for tol in tolerances:
        bad = {k for k, e in zip(kc.tolist(), ec.tolist()) if e > max(tol, fine_err.get(k, 0.0))}
        fails_f = np.fromiter((k in bad for k in kf.tolist()), bool, len(kf))
        fails_c = np.fromiter((k in bad for k in kc.tolist()), bool, len(kc))
        r["tolerances"][tol] = {"skipped": 1.0 - fails_f.mean(),
                                "triangles": int((~fails_c).sum() + fails_f.sum())}
    return r
