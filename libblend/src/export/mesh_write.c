/* Mesh files: binary PLY, OBJ, binary STL, glTF binary (.glb).
 * Every writer streams into an lb_output (libblend/output.h), which puts the
 * file in place only when everything was written and closed: a failure
 * never leaves a partial file. Binary formats are little-endian by spec and
 * are written byte by byte here, whatever the host. */
#define _POSIX_C_SOURCE 200809L
#include "libblend/output.h"

#include "../common/internal.h"

#include <libblend/mesh.h>

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char FN[] = "lb_mesh_write";

static void put_u32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static void put_f32(unsigned char *p, double v) {
    const float f = (float)v;
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_u32(p, u);
}

/* vertices as float32 x y z nx ny nz, little-endian */
static int write_vertices_f32(FILE *f, const lb_mesh *m, int with_normals) {
    unsigned char buf[24];
    for (size_t i = 0; i < m->nvertices; ++i) {
        for (int d = 0; d < 3; ++d) put_f32(buf + 4 * d, m->positions[3 * i + d]);
        if (with_normals)
            for (int d = 0; d < 3; ++d) put_f32(buf + 12 + 4 * d, m->normals[3 * i + d]);
        if (fwrite(buf, with_normals ? 24 : 12, 1, f) != 1) return 0;
    }
    return 1;
}

static int write_ply(FILE *f, const lb_mesh *m) {
    if (fprintf(f,
                "ply\nformat binary_little_endian 1.0\ncomment written by libblend\n"
                "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\n"
                "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
                m->nvertices, m->ntriangles) < 0)
        return 0;
    if (!write_vertices_f32(f, m, 1)) return 0;
    unsigned char buf[13];
    buf[0] = 3;
    for (size_t t = 0; t < m->ntriangles; ++t) {
        for (int c = 0; c < 3; ++c) put_u32(buf + 1 + 4 * c, m->triangles[3 * t + c]);
        if (fwrite(buf, 13, 1, f) != 1) return 0;
    }
    return 1;
}

static int write_obj(FILE *f, const lb_mesh *m) {
    if (fprintf(f, "# written by libblend: %zu vertices, %zu triangles\n", m->nvertices,
                m->ntriangles) < 0)
        return 0;
    for (size_t i = 0; i < m->nvertices; ++i)
        if (fprintf(f, "v %.17g %.17g %.17g\n", m->positions[3 * i], m->positions[3 * i + 1],
                    m->positions[3 * i + 2]) < 0)
            return 0;
    const size_t nn = m->corner_normals ? m->nnormals : m->nvertices;
    for (size_t i = 0; i < nn; ++i)
        if (fprintf(f, "vn %.9g %.9g %.9g\n", m->normals[3 * i], m->normals[3 * i + 1],
                    m->normals[3 * i + 2]) < 0)
            return 0;
    const uint32_t *cn = m->corner_normals ? m->corner_normals : m->triangles;
    for (size_t t = 0; t < m->ntriangles; ++t) {
        const uint32_t *v = m->triangles + 3 * t, *n = cn + 3 * t;
        if (fprintf(f, "f %lu//%lu %lu//%lu %lu//%lu\n", v[0] + 1ul, n[0] + 1ul, v[1] + 1ul,
                    n[1] + 1ul, v[2] + 1ul, n[2] + 1ul) < 0)
            return 0;
    }
    return 1;
}

static int write_stl(FILE *f, const lb_mesh *m) {
    unsigned char head[84];
    memset(head, 0, sizeof head);
    snprintf((char *)head, 80, "libblend binary STL");
    if (m->ntriangles > UINT32_MAX) return 0;
    put_u32(head + 80, (uint32_t)m->ntriangles);
    if (fwrite(head, sizeof head, 1, f) != 1) return 0;
    unsigned char buf[50];
    memset(buf, 0, sizeof buf);
    for (size_t t = 0; t < m->ntriangles; ++t) {
        const double *p[3];
        for (int c = 0; c < 3; ++c) p[c] = m->positions + 3 * (size_t)m->triangles[3 * t + c];
        const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
        const double v[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int d = 0; d < 3; ++d) put_f32(buf + 4 * d, l > 0.0 ? n[d] / l : 0.0);
        for (int c = 0; c < 3; ++c)
            for (int d = 0; d < 3; ++d) put_f32(buf + 12 + 12 * c + 4 * d, p[c][d]);
        if (fwrite(buf, 50, 1, f) != 1) return 0;
    }
    return 1;
}

/* glTF 2.0 binary: one mesh, one primitive (POSITION, NORMAL, uint32
 * indices), the JSON built with cJSON. glTF has one normal per vertex, so
 * with corner normals vertex i < nvertices is vertex i and vertex i >=
 * nvertices a copy of the vertex whose corners use normal i (owner, from
 * check_mesh); every corner then names the copy of its normal. */
static int write_glb(FILE *f, const lb_mesh *m, const uint32_t *owner) {
    const size_t nout = m->corner_normals ? m->nnormals : m->nvertices;
    const uint32_t *idx = m->corner_normals ? m->corner_normals : m->triangles;
    const size_t vbytes = 12 * nout, ibytes = 12 * m->ntriangles;
    const size_t bin = 2 * vbytes + ibytes; /* every part is a multiple of 4 */
    if (bin > UINT32_MAX / 2) return 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < m->nvertices; ++i) /* the copies add no position */
        for (int d = 0; d < 3; ++d) {
            const double x = (float)m->positions[3 * i + d];
            if (i == 0 || x < lo[d]) lo[d] = x;
            if (i == 0 || x > hi[d]) hi[d] = x;
        }
    cJSON *root = cJSON_CreateObject();
    int ok = root != NULL;
    char *json = NULL;
    if (ok) {
        cJSON *asset = cJSON_AddObjectToObject(root, "asset");
        cJSON_AddStringToObject(asset, "version", "2.0");
        cJSON_AddStringToObject(asset, "generator", "libblend");
        cJSON_AddNumberToObject(root, "scene", 0);
        cJSON *scenes = cJSON_AddArrayToObject(root, "scenes");
        cJSON *scene = cJSON_CreateObject();
        cJSON_AddItemToArray(scenes, scene);
    }
    /* an empty mesh is a scene without nodes: glTF allows no empty
     * accessor, buffer view or buffer */
    if (ok && m->ntriangles) {
        const int zero = 0;
        cJSON *scene = cJSON_GetArrayItem(cJSON_GetObjectItem(root, "scenes"), 0);
        cJSON_AddItemToObject(scene, "nodes", cJSON_CreateIntArray(&zero, 1));
        cJSON *nodes = cJSON_AddArrayToObject(root, "nodes");
        cJSON *node = cJSON_CreateObject();
        cJSON_AddItemToArray(nodes, node);
        cJSON_AddNumberToObject(node, "mesh", 0);
        cJSON *meshes = cJSON_AddArrayToObject(root, "meshes");
        cJSON *mesh = cJSON_CreateObject();
        cJSON_AddItemToArray(meshes, mesh);
        cJSON *prims = cJSON_AddArrayToObject(mesh, "primitives");
        cJSON *prim = cJSON_CreateObject();
        cJSON_AddItemToArray(prims, prim);
        cJSON *attr = cJSON_AddObjectToObject(prim, "attributes");
        cJSON_AddNumberToObject(attr, "POSITION", 0);
        cJSON_AddNumberToObject(attr, "NORMAL", 1);
        cJSON_AddNumberToObject(prim, "indices", 2);
        cJSON_AddNumberToObject(prim, "mode", 4);
        cJSON *buffers = cJSON_AddArrayToObject(root, "buffers");
        cJSON *buffer = cJSON_CreateObject();
        cJSON_AddItemToArray(buffers, buffer);
        cJSON_AddNumberToObject(buffer, "byteLength", (double)bin);
        cJSON *views = cJSON_AddArrayToObject(root, "bufferViews");
        const size_t off[3] = {0, vbytes, 2 * vbytes}, len[3] = {vbytes, vbytes, ibytes};
        for (int i = 0; i < 3; ++i) {
            cJSON *v = cJSON_CreateObject();
            cJSON_AddItemToArray(views, v);
            cJSON_AddNumberToObject(v, "buffer", 0);
            cJSON_AddNumberToObject(v, "byteOffset", (double)off[i]);
            cJSON_AddNumberToObject(v, "byteLength", (double)len[i]);
            cJSON_AddNumberToObject(v, "target", i < 2 ? 34962 : 34963);
        }
        cJSON *accs = cJSON_AddArrayToObject(root, "accessors");
        for (int i = 0; i < 3; ++i) {
            cJSON *a = cJSON_CreateObject();
            cJSON_AddItemToArray(accs, a);
            cJSON_AddNumberToObject(a, "bufferView", i);
            cJSON_AddNumberToObject(a, "componentType", i < 2 ? 5126 : 5125);
            cJSON_AddNumberToObject(a, "count", (double)(i < 2 ? nout : 3 * m->ntriangles));
            cJSON_AddStringToObject(a, "type", i < 2 ? "VEC3" : "SCALAR");
            if (i == 0) {
                cJSON_AddItemToObject(a, "min", cJSON_CreateDoubleArray(lo, 3));
                cJSON_AddItemToObject(a, "max", cJSON_CreateDoubleArray(hi, 3));
            }
        }
    }
    if (ok) {
        json = cJSON_PrintUnformatted(root);
        ok = json != NULL;
    }
    cJSON_Delete(root);
    if (!ok) return 0;
    const size_t jlen = strlen(json), jpad = (4 - jlen % 4) % 4;
    unsigned char h[20];
    memcpy(h, "glTF", 4);
    put_u32(h + 4, 2);
    put_u32(h + 8, (uint32_t)(12 + 8 + jlen + jpad + (bin ? 8 + bin : 0)));
    put_u32(h + 12, (uint32_t)(jlen + jpad));
    memcpy(h + 16, "JSON", 4);
    ok = fwrite(h, 20, 1, f) == 1 && fwrite(json, 1, jlen, f) == jlen &&
         fwrite("   ", 1, jpad, f) == jpad;
    free(json);
    if (!ok) return 0;
    if (!bin) return 1;
    put_u32(h, (uint32_t)bin);
    memcpy(h + 4, "BIN\0", 4);
    if (fwrite(h, 8, 1, f) != 1) return 0;
    unsigned char buf[12];
    for (size_t i = 0; i < nout; ++i) {
        const size_t v = i < m->nvertices ? i : owner[i - m->nvertices];
        for (int d = 0; d < 3; ++d) put_f32(buf + 4 * d, m->positions[3 * v + d]);
        if (fwrite(buf, 12, 1, f) != 1) return 0;
    }
    for (size_t i = 0; i < nout; ++i) {
        for (int d = 0; d < 3; ++d) put_f32(buf + 4 * d, m->normals[3 * i + d]);
        if (fwrite(buf, 12, 1, f) != 1) return 0;
    }
    for (size_t t = 0; t < m->ntriangles; ++t) {
        for (int c = 0; c < 3; ++c) put_u32(buf + 4 * c, idx[3 * t + c]);
        if (fwrite(buf, 12, 1, f) != 1) return 0;
    }
    return 1;
}

/* The mesh's indices in range: every triangle's vertices below nvertices;
 * with corner normals, each corner's normal its own vertex's or one at or
 * above nvertices used by corners of one vertex only (its owner, written to
 * owner[n - nvertices] for glTF's copies). A message naming the first
 * triangle that breaks this, or LB_OK. */
static lb_status check_mesh(const lb_mesh *m, const char *where, uint32_t **owner, lb_error *err) {
    *owner = NULL;
    if ((m->ntriangles && !m->triangles) || (m->nvertices && (!m->positions || !m->normals)))
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: the mesh's arrays are missing", where);
    for (size_t c = 0; c < 3 * m->ntriangles; ++c)
        if (m->triangles[c] >= m->nvertices)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: triangle %zu names vertex %u of %zu; nothing was written", where,
                            c / 3, (unsigned)m->triangles[c], m->nvertices);
    if (!m->corner_normals) return LB_OK;
    if (m->nnormals < m->nvertices || m->nnormals - m->nvertices > UINT32_MAX)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: nnormals %zu is below nvertices %zu; nothing was written", where,
                        m->nnormals, m->nvertices);
    const size_t nx = m->nnormals - m->nvertices;
    uint32_t *o = malloc((nx ? nx : 1) * sizeof *o);
    if (!o) return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", where);
    for (size_t i = 0; i < nx; ++i) o[i] = UINT32_MAX;
    for (size_t c = 0; c < 3 * m->ntriangles; ++c) {
        const uint32_t n = m->corner_normals[c], v = m->triangles[c];
        const int ok = n < m->nvertices ? n == v
                                        : n < m->nnormals && (o[n - m->nvertices] == UINT32_MAX ||
                                                              o[n - m->nvertices] == v);
        if (!ok) {
            free(o);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: triangle %zu's corner %zu has normal %u, neither its vertex's "
                            "(%u) nor one of the %zu added normals of that vertex alone; "
                            "nothing was written",
                            where, c / 3, c % 3, (unsigned)n, (unsigned)v, nx);
        }
        if (n >= m->nvertices) o[n - m->nvertices] = v;
    }
    for (size_t i = 0; i < nx; ++i)
        if (o[i] == UINT32_MAX) o[i] = 0; /* a normal no corner uses: any position will do */
    *owner = o;
    return LB_OK;
}

static lb_mesh_format format_of(const char *path) {
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) return LB_MESH_FORMAT_AUTO;
    if (strcasecmp(dot, ".ply") == 0) return LB_MESH_FORMAT_PLY;
    if (strcasecmp(dot, ".obj") == 0) return LB_MESH_FORMAT_OBJ;
    if (strcasecmp(dot, ".stl") == 0) return LB_MESH_FORMAT_STL;
    if (strcasecmp(dot, ".glb") == 0) return LB_MESH_FORMAT_GLB;
    return LB_MESH_FORMAT_AUTO;
}

static int write_format(FILE *f, const lb_mesh *mesh, lb_mesh_format format,
                        const uint32_t *owner) {
    switch (format) {
    case LB_MESH_FORMAT_PLY:
        return write_ply(f, mesh);
    case LB_MESH_FORMAT_OBJ:
        return write_obj(f, mesh);
    case LB_MESH_FORMAT_STL:
        return write_stl(f, mesh);
    default:
        return write_glb(f, mesh, owner);
    }
}

lb_status lb_mesh_write_stream(const lb_mesh *mesh, FILE *stream, lb_mesh_format format,
                               lb_error *err) {
    if (!mesh || !stream)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_mesh_write_stream: mesh and stream must "
                        "be given");
    if (format < LB_MESH_FORMAT_PLY || format > LB_MESH_FORMAT_GLB)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "lb_mesh_write_stream: format %d; allowed: LB_MESH_FORMAT_PLY, _OBJ, "
                        "_STL or _GLB",
                        (int)format);
    uint32_t *owner = NULL;
    const lb_status s = check_mesh(mesh, "lb_mesh_write_stream", &owner, err);
    if (s) return s;
    const int ok =
        write_format(stream, mesh, format, owner) && fflush(stream) == 0 && !ferror(stream);
    free(owner);
    if (!ok)
        return lb__fail(err, LB_ERR_IO, "lb_mesh_write_stream: writing failed (%s)",
                        strerror(errno));
    return LB_OK;
}

lb_mesh_format lb_mesh_format_of(const char *path) {
    return path ? format_of(path) : LB_MESH_FORMAT_AUTO;
}

lb_status lb_mesh_write(const lb_mesh *mesh, const char *path, lb_mesh_format format,
                        lb_error *err) {
    if (!mesh || !path || !*path)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: mesh and path must be given", FN);
    if (format == LB_MESH_FORMAT_AUTO) format = format_of(path);
    if (format < LB_MESH_FORMAT_PLY || format > LB_MESH_FORMAT_GLB)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: %s: unknown mesh format; allowed: a name ending in .ply, .obj, "
                        ".stl or .glb",
                        FN, path);
    uint32_t *owner = NULL;
    lb_status s = check_mesh(mesh, FN, &owner, err);
    if (s) return s;
    lb_output *o = NULL;
    s = lb_output_open(path, &o, err);
    if (s) {
        free(owner);
        return s;
    }
    const int ok = write_format(lb_output_stream(o), mesh, format, owner);
    free(owner);
    if (!ok) {
        const int e = errno;
        lb_output_discard(o);
        return lb__fail(err, LB_ERR_IO, "%s: %s: writing failed (%s); nothing was written", FN,
                        path, e ? strerror(e) : "short write");
    }
    return lb_output_commit(o, err);
}
