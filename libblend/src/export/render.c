/* Render defaults shared by the exporters (POV-Ray here, Blender through
 * ctypes): the three-point lights around a camera and the floor under the
 * surface. One definition, so both renderers light and ground a scene the
 * same way. */
#include "../common/internal.h"

#include <libblend/mesh.h>
#include <libblend/pov.h>

#include <math.h>
#include <string.h>

/* key, fill, rim: (right, up, forward) in units of the camera's distance to
 * its target, and strength */
static const double PLACE[3][3] = {{-0.7, 0.9, -0.5}, {1.0, 0.2, -0.6}, {0.4, 1.0, 1.1}};
static const double STRENGTH[3] = {0.85, 0.35, 0.5};

/* a made unit; its length in *len (may be NULL). Scaled by the largest
 * component first, so that no square overflows (a camera 1e200 away) or
 * underflows. 0 when a is zero or not finite. */
static int unit(double a[3], double *len) {
    const double m = fmax(fabs(a[0]), fmax(fabs(a[1]), fabs(a[2])));
    if (!(m > 0.0) || !isfinite(m)) return 0;
    for (int d = 0; d < 3; ++d) a[d] /= m;
    const double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int d = 0; d < 3; ++d) a[d] /= l;
    if (len) *len = m * l;
    return len ? isfinite(*len) : 1;
}

void lb_render_three_point(const double loc[3], const double at[3], const double up[3],
                           lb_render_light lights[3]) {
    if (!loc || !at || !up || !lights) return;
    double F[3] = {at[0] - loc[0], at[1] - loc[1], at[2] - loc[2]}, R[3], U[3], L = 0.0;
    if (!unit(F, &L)) return;
    R[0] = F[1] * up[2] - F[2] * up[1];
    R[1] = F[2] * up[0] - F[0] * up[2];
    R[2] = F[0] * up[1] - F[1] * up[0];
    if (!unit(R, NULL)) return;
    for (int k = 0; k < 3; ++k) /* the lights must be representable too */
        for (int d = 0; d < 3; ++d)
            if (!isfinite(at[d] + L * (PLACE[k][0] * R[d] + PLACE[k][2] * F[d]) + L * PLACE[k][1]))
                return;
    U[0] = R[1] * F[2] - R[2] * F[1];
    U[1] = R[2] * F[0] - R[0] * F[2];
    U[2] = R[0] * F[1] - R[1] * F[0];
    for (int k = 0; k < 3; ++k)
        for (int d = 0; d < 3; ++d) {
            lights[k].location[d] =
                at[d] + L * (PLACE[k][0] * R[d] + PLACE[k][1] * U[d] + PLACE[k][2] * F[d]);
            lights[k].color[d] = STRENGTH[k];
        }
}

lb_status lb_render_floor_height(const lb_evaluator *ev, const double bmin[3], const double bmax[3],
                                 const double up[3], int threads, double *height, lb_error *err) {
    if (!ev || !bmin || !bmax || !up || !height)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_render_floor_height: ev, bmin, bmax, up and height must be given");
    if (threads < 0)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_render_floor_height: threads = %d; allowed: 0 (one per CPU) or more",
                        threads);
    for (int d = 0; d < 3; ++d)
        if (!(fabs(bmin[d]) <= LB_SCENE_MAX_COORD) || !(fabs(bmax[d]) <= LB_SCENE_MAX_COORD) ||
            !(bmin[d] < bmax[d]))
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "lb_render_floor_height: box %c range [%g, %g]; allowed: finite, "
                            "min < max, |coordinate| <= %g",
                            "xyz"[d], bmin[d], bmax[d], LB_SCENE_MAX_COORD);
    if (!(isfinite(up[0]) && isfinite(up[1]) && isfinite(up[2])) ||
        (up[0] == 0.0 && up[1] == 0.0 && up[2] == 0.0))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_render_floor_height: up = (%g, %g, %g); allowed: a finite, non-zero "
                        "direction",
                        up[0], up[1], up[2]);
    double h = INFINITY;
    for (int c = 0; c < 8; ++c) {
        double t = 0.0;
        for (int d = 0; d < 3; ++d) t += up[d] * ((c >> d) & 1 ? bmax[d] : bmin[d]);
        if (t < h) h = t;
    }
    if (!isfinite(h))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_render_floor_height: the box or up is not finite");
    lb_mesh_options o;
    lb_mesh_options_init(&o);
    memcpy(o.bmin, bmin, sizeof o.bmin);
    memcpy(o.bmax, bmax, sizeof o.bmax);
    o.resolution = 48;
    o.threads = threads;
    lb_mesh *m = NULL;
    if (lb_mesh_create(ev, &o, &m, NULL) == LB_OK && m->nvertices) {
        double lo = INFINITY;
        for (size_t i = 0; i < m->nvertices; ++i) {
            const double *X = m->positions + 3 * i;
            const double t = up[0] * X[0] + up[1] * X[1] + up[2] * X[2];
            if (t < lo) lo = t;
        }
        /* a coarse mesh's lowest vertex is within a cell of the surface's */
        double cell = m->cell[0] > m->cell[1] ? m->cell[0] : m->cell[1];
        if (m->cell[2] > cell) cell = m->cell[2];
        lo -= 0.5 * cell * sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
        if (lo > h) h = lo;
    }
    lb_mesh_free(m);
    *height = h;
    return LB_OK;
}
