/* The layout of every public struct the ctypes binding mirrors
 * (blender_addon_c/libblend_blender/binding.py), as the C compiler lays it
 * out: one JSON object of sizes and field offsets, compared with the
 * binding's by test_abi_layout.py. A field appended in C and not in Python
 * would make the library read or write past the binding's buffer. */
#include <libblend/libblend.h>

#include <stddef.h>
#include <stdio.h>

#define FIELD(T, f) printf("%s\"%s\": %zu", first++ ? ", " : "", #f, offsetof(T, f))
#define BEGIN(T, py)                                                                               \
    do {                                                                                           \
        printf("%s\"%s\": {\"size\": %zu, \"fields\": {", nstruct++ ? ",\n " : "", py, sizeof(T)); \
        first = 0;                                                                                 \
    } while (0)
#define END() printf("}}")

int main(void) {
    int nstruct = 0, first = 0;
    printf("{");
    BEGIN(lb_error, "_Error");
    FIELD(lb_error, status);
    FIELD(lb_error, message);
    END();
    BEGIN(lb_mesh_options, "_MeshOptions");
    FIELD(lb_mesh_options, bmin);
    FIELD(lb_mesh_options, bmax);
    FIELD(lb_mesh_options, resolution);
    FIELD(lb_mesh_options, cell_size);
    FIELD(lb_mesh_options, flags);
    FIELD(lb_mesh_options, threads);
    FIELD(lb_mesh_options, max_memory);
    FIELD(lb_mesh_options, progress);
    FIELD(lb_mesh_options, user);
    FIELD(lb_mesh_options, cancel);
    FIELD(lb_mesh_options, simplify);
    END();
    BEGIN(lb_mesh, "_Mesh");
    FIELD(lb_mesh, nvertices);
    FIELD(lb_mesh, ntriangles);
    FIELD(lb_mesh, positions);
    FIELD(lb_mesh, normals);
    FIELD(lb_mesh, triangles);
    FIELD(lb_mesh, origin);
    FIELD(lb_mesh, cell);
    FIELD(lb_mesh, cells);
    FIELD(lb_mesh, nnormals);
    FIELD(lb_mesh, corner_normals);
    END();
    BEGIN(lb_pov_options, "_PovOptions");
    FIELD(lb_pov_options, include_only);
    FIELD(lb_pov_options, silhouette);
    FIELD(lb_pov_options, aspect);
    FIELD(lb_pov_options, max_gradient);
    FIELD(lb_pov_options, threads);
    FIELD(lb_pov_options, mesh_resolution);
    FIELD(lb_pov_options, mesh_features);
    FIELD(lb_pov_options, mesh_simplify);
    FIELD(lb_pov_options, mesh_merge_flat);
    END();
    BEGIN(lb_material, "_Material");
    FIELD(lb_material, color);
    FIELD(lb_material, ambient);
    FIELD(lb_material, diffuse);
    FIELD(lb_material, specular);
    END();
    BEGIN(lb_render_light, "_Light");
    FIELD(lb_render_light, location);
    FIELD(lb_render_light, color);
    END();
    BEGIN(lb_scene_stats, "_Stats");
    FIELD(lb_scene_stats, nodes);
    FIELD(lb_scene_stats, primitives);
    FIELD(lb_scene_stats, operators);
    FIELD(lb_scene_stats, depth);
    END();
    BEGIN(lb_mesh_cache_stats, "_CacheStats");
    FIELD(lb_mesh_cache_stats, blocks);
    FIELD(lb_mesh_cache_stats, reused);
    FIELD(lb_mesh_cache_stats, recycled);
    FIELD(lb_mesh_cache_stats, bytes);
    END();
    printf("}\n");
    return 0;
}
