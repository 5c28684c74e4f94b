/* lbvdb: blendtool's OpenVDB files, C++ behind a plain C interface
 * (OpenVDB has no C API). Like lbimageio, a module blendtool loads with
 * dlopen on first use: libblend.so stays C, and the C++ libraries are not
 * mapped when blendtool only meshes or renders.
 *
 * The writer returns the file's bytes in a malloc'd buffer the caller frees
 * (the caller puts them in place atomically, through lb_output). Nothing in
 * the file depends on the time or the run: OpenVDB's per-file UUID is
 * derived from the caller's uuid_seed, so the same level set and metadata
 * give the same bytes on every run and machine. Returns 0, or -1 with a
 * message in err (always NUL-terminated when errlen > 0). */
#ifndef LBVDB_H
#define LBVDB_H

#include <libblend/volume.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* one metadata entry: a string on every grid of the file */
typedef struct lbv_meta {
    const char *key, *value;
} lbv_meta;

/* The level set as an OpenVDB file: a float grid named "surface" of class
 * level set (background ls->background, linear transform of voxel size
 * ls->voxel_size, the band's voxels active, the sign of everything else
 * filled in from the band by OpenVDB's signed flood fill); with
 * ls->fields a float grid "value" (the field f on the band's voxels,
 * background 0) and with ls->gradients a vector grid "gradient"
 * (covariant, grad f on the band's voxels). uuid_seed: 32 hex digits.
 * shift: added to every voxel's world position, in voxels on each axis (0:
 * voxel (i, j, k) at (i h, j h, k h), OpenVDB's and Houdini's reading;
 * -0.5: where Blender, which puts a voxel's centre at index + 1/2, shows it
 * at (i h, j h, k h)). threads: OpenVDB's threads for the call (its TBB
 * workers), 0 for one per CPU; 1 makes no thread. The bytes are the same for
 * every count. */
int lbv_level_set_file(const lb_level_set *ls, double shift, const lbv_meta *meta, size_t nmeta,
                       const char *uuid_seed, unsigned threads, unsigned char **data, size_t *size,
                       char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
