/* Every scene the suite runs on: scenes/ and tests/data/scenes/ under
 * SOURCE_DIR. Include after testlib.h, with _POSIX_C_SOURCE defined. */
#ifndef LIBBLEND_SCENELIST_H
#define LIBBLEND_SCENELIST_H

#include <dirent.h>

#ifndef SOURCE_DIR
#error "SOURCE_DIR must be defined"
#endif

#define MAX_SCENES 64

static char scene_paths[MAX_SCENES][1024];
static size_t nscenes;

/* Fills scene_paths; returns 0 when at least 17 scenes were found. */
static inline int collect_scenes(void) {
    static const char *const dirs[2] = {"scenes", "tests/data/scenes"};
    for (int i = 0; i < 2; ++i) {
        char full[512];
        snprintf(full, sizeof full, "%s/%s", SOURCE_DIR, dirs[i]);
        DIR *d = opendir(full);
        if (!d) return -1;
        struct dirent *e;
        while ((e = readdir(d)) && nscenes < MAX_SCENES) {
            const size_t len = strlen(e->d_name);
            if (len > 5 && strcmp(e->d_name + len - 5, ".json") == 0)
                snprintf(scene_paths[nscenes++], sizeof scene_paths[0], "%.500s/%.500s", full,
                         e->d_name);
        }
        closedir(d);
    }
    return nscenes >= 17 ? 0 : -1;
}

#endif
