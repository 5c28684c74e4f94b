/* lb_mesh_edges: the mesh's undirected edges, and the edge of every
 * triangle corner, for hosts that store edges explicitly (Blender's meshes
 * do; deriving them there costs more than meshing a frame's worth of
 * triangles, bench/run_blender_anim_bench.sh).
 *
 * Corner c of triangle t (index 3t + c) goes from vertex triangles[3t + c]
 * to triangles[3t + (c + 1) % 3]; its edge is that unordered pair. Edges are
 * numbered in order of first appearance over the corners, and stored with
 * the smaller vertex index first, so the result depends only on the
 * triangles.
 *
 * One counting sort of the corners by their smaller vertex gives each
 * vertex a bucket with room for every corner that starts an edge there;
 * walking the corners in order, a corner finds its edge in its bucket (a
 * handful of entries: a vertex's degree) or appends it. Linear time, two
 * passes, no hashing. */
#include "mesh_internal.h"

#include <stdlib.h>

lb_status lb_mesh_edges(const lb_mesh *mesh, uint32_t *edges, uint32_t *corner_edge, size_t *nedges,
                        lb_error *err) {
    static const char fn[] = "lb_mesh_edges";
    if (nedges) *nedges = 0;
    if (!mesh || !nedges || (mesh->ntriangles && (!edges || !corner_edge)))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: mesh and nedges must be non-NULL, and edges and corner_edge too "
                        "when the mesh has triangles",
                        fn);
    const size_t nt = mesh->ntriangles, nv = mesh->nvertices, nc = 3 * nt;
    if (nt == 0) return LB_OK;
    if (nc > UINT32_MAX)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: %zu triangles; allowed: at most %u (32-bit corner indices)", fn, nt,
                        (unsigned)(UINT32_MAX / 3));
    const uint32_t *T = mesh->triangles;
    if (!T)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: the mesh has %zu triangles but no triangle array; allowed: a mesh "
                        "from lb_mesh_create, or triangles non-NULL whenever ntriangles > 0",
                        fn, nt);
    for (size_t q = 0; q < nc; ++q)
        if (T[q] >= nv)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: triangle %zu names vertex %u; allowed: below %zu vertices", fn,
                            q / 3, (unsigned)T[q], nv);
    size_t *start = calloc(nv + 1, sizeof *start);
    uint32_t *used = calloc(nv, sizeof *used);
    uint32_t *slot = malloc(2 * nc * sizeof *slot); /* (other vertex, edge) per entry */
    if (!start || !used || !slot) {
        free(start);
        free(used);
        free(slot);
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", fn);
    }
    for (size_t q = 0; q < nc; ++q) {
        const uint32_t a = T[q], b = T[q - q % 3 + (q % 3 + 1) % 3];
        start[(a < b ? a : b) + 1]++;
    }
    for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    uint32_t ne = 0;
    for (size_t q = 0; q < nc; ++q) {
        const uint32_t a = T[q], b = T[q - q % 3 + (q % 3 + 1) % 3];
        const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
        uint32_t *s = slot + 2 * start[lo];
        uint32_t i = 0;
        while (i < used[lo] && s[2 * i] != hi) ++i;
        if (i == used[lo]) { /* first corner on this edge */
            s[2 * i] = hi;
            s[2 * i + 1] = ne;
            edges[2 * ne] = lo;
            edges[2 * ne + 1] = hi;
            ++ne;
            ++used[lo];
        }
        corner_edge[q] = s[2 * i + 1];
    }
    free(start);
    free(used);
    free(slot);
    *nedges = ne;
    return LB_OK;
}
