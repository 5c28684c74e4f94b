/* The POV-Ray writer's mesh geometry (lb_pov_options.mesh_resolution): the
 * surface as libblend's own closed mesh, written as a mesh2 of smooth
 * triangles. POV-Ray stores a mesh's vertices and normals in single
 * precision, so nine significant digits carry every bit it keeps. With
 * mesh_features the corners on a crease name their side's normal through
 * normal_indices (a normal per triangle corner, into normal_vectors), so
 * POV-Ray shades the crease sharp. */
#include "pov_internal.h"

lb_status lb__pov_mesh(sbuf *b, const lb_evaluator *ev, const double lo[3], const double hi[3],
                       const lb_pov_options *o, int *empty, lb_error *err) {
    const int resolution = o->mesh_resolution;
    *empty = 0;
    if (resolution < 1 || resolution > LB_POV_MAX_MESH_RESOLUTION)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: mesh_resolution %d; allowed: 1 to %d cells (0 for the isosurface)", FN,
                        resolution, LB_POV_MAX_MESH_RESOLUTION);
    lb_mesh_options mo;
    lb_mesh_options_init(&mo);
    for (int d = 0; d < 3; ++d) {
        mo.bmin[d] = lo[d];
        mo.bmax[d] = hi[d];
    }
    mo.resolution = (unsigned)resolution;
    mo.threads = o->threads;
    mo.simplify = o->mesh_simplify;
    if (o->mesh_features) mo.flags = LB_MESH_FEATURES | LB_MESH_CORNER_NORMALS;
    if (o->mesh_merge_flat) mo.flags |= LB_MESH_MERGE_FLAT;
    lb_mesh *m = NULL;
    const lb_status s = lb_mesh_create(ev, &mo, &m, err);
    if (s) return s;
    const size_t nv = m->nvertices, nt = m->ntriangles, nn = m->nnormals;
    if (!nt) {
        /* POV-Ray refuses a mesh2 without faces: no object at all */
        *empty = 1;
        lb_mesh_free(m);
        return LB_OK;
    }
    sb(b, "%s %zu vertices, %zu triangles at %d cells\nmesh2 {\n  vertex_vectors { %zu",
       LB_POV_VERBATIM_BEGIN, nv, nt, resolution, nv);
    for (size_t i = 0; i < nv; ++i) {
        const double *p = m->positions + 3 * i;
        sb(b, ",\n    <%.9g, %.9g, %.9g>", p[0], p[1], p[2]);
    }
    sb(b, " }\n  normal_vectors { %zu", nn);
    for (size_t i = 0; i < nn; ++i) {
        const double *n = m->normals + 3 * i;
        sb(b, ",\n    <%.9g, %.9g, %.9g>", n[0], n[1], n[2]);
    }
    sb(b, " }\n  face_indices { %zu", nt);
    for (size_t t = 0; t < nt; ++t) {
        const uint32_t *v = m->triangles + 3 * t;
        sb(b, ",\n    <%u, %u, %u>", (unsigned)v[0], (unsigned)v[1], (unsigned)v[2]);
    }
    if (m->corner_normals) { /* a normal per corner: each side of a crease its own */
        sb(b, " }\n  normal_indices { %zu", nt);
        for (size_t t = 0; t < nt; ++t) {
            const uint32_t *n = m->corner_normals + 3 * t;
            sb(b, ",\n    <%u, %u, %u>", (unsigned)n[0], (unsigned)n[1], (unsigned)n[2]);
        }
    }
    sb(b, " }\n" LB_POV_VERBATIM_END "\n  ");
    lb_mesh_free(m);
    return LB_OK;
}
