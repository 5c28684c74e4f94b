/* lb_mesh_velocities: how fast each vertex of a moving surface moves, for
 * motion blur (a mesh whose topology changes every frame cannot be blurred
 * by matching vertices between frames).
 *
 * The surface is the level set f(x, t) = c. Following a point on it,
 * d/dt f(x(t), t) = 0, so grad f . x' = -df/dt: the surface moves along its
 * normal at speed -(df/dt) / |grad f|, and the velocity of the point that
 * moves straight along the normal is -(df/dt) grad f / |grad f|^2, in both
 * conventions (the sign of grad f cancels). The motion along the surface
 * cannot be seen in the field and is taken as zero: a translating sphere's
 * vertices get the normal part of its velocity, which is what a renderer's
 * blur of the silhouette needs. df/dt is a central difference of the
 * fields before and after (one-sided when only one is given). */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>

#define CHUNK 4096

lb_status lb_mesh_velocities(const lb_evaluator *ev, const lb_evaluator *before,
                             const lb_evaluator *after, const lb_mesh *mesh, double dt, int threads,
                             double *velocities, lb_error *err) {
    static const char fn[] = "lb_mesh_velocities";
    if (!ev || !mesh || (!before && !after) ||
        (mesh->nvertices && (!mesh->positions || !velocities)))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: ev, mesh and at least one of before and after must be non-NULL, "
                        "and the mesh's positions and velocities too when it has vertices",
                        fn);
    if (!(dt > 0.0) || !isfinite(dt))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: dt %g; allowed: a finite time step > 0",
                        fn, dt);
    const lb_convention conv = lb_evaluator_convention(ev);
    if ((before && lb_evaluator_convention(before) != conv) ||
        (after && lb_evaluator_convention(after) != conv))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the fields before and after must have ev's convention (%s)", fn,
                        conv == LB_CONVENTION_SOFT ? "soft" : "zero");
    const size_t n = mesh->nvertices;
    double *mem = malloc(9 * CHUNK * sizeof *mem);
    if (!mem) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", fn);
    double *x = mem, *y = x + CHUNK, *z = y + CHUNK, *f = z + CHUNK, *gx = f + CHUNK,
           *gy = gx + CHUNK, *gz = gy + CHUNK, *fb = gz + CHUNK, *fa = fb + CHUNK;
    /* the time between the two fields sampled */
    const double span = (before && after ? 2.0 : 1.0) * dt;
    lb_status s = LB_OK;
    for (size_t start = 0; start < n && !s; start += CHUNK) {
        const size_t m = n - start < CHUNK ? n - start : CHUNK;
        for (size_t i = 0; i < m; ++i) {
            const double *p = mesh->positions + 3 * (start + i);
            x[i] = p[0], y[i] = p[1], z[i] = p[2];
        }
        s = lb_evaluator_eval(ev, m, x, y, z, f, gx, gy, gz, threads, err);
        if (!s && before)
            s = lb_evaluator_eval(before, m, x, y, z, fb, NULL, NULL, NULL, threads, err);
        if (!s && after)
            s = lb_evaluator_eval(after, m, x, y, z, fa, NULL, NULL, NULL, threads, err);
        for (size_t i = 0; i < m && !s; ++i) {
            double *v = velocities + 3 * (start + i);
            const double hi = after ? fa[i] : f[i], lo = before ? fb[i] : f[i];
            const double dfdt = (hi - lo) / span;
            const double g2 = gx[i] * gx[i] + gy[i] * gy[i] + gz[i] * gz[i];
            /* no gradient (a crease's tip, a flat spot) or no finite value:
             * no known motion */
            if (!(g2 > 0.0) || !isfinite(dfdt) || !isfinite(g2)) {
                v[0] = v[1] = v[2] = 0.0;
                continue;
            }
            const double k = -dfdt / g2;
            v[0] = k * gx[i], v[1] = k * gy[i], v[2] = k * gz[i];
            if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])) v[0] = v[1] = v[2] = 0.0;
        }
    }
    free(mem);
    return s;
}
