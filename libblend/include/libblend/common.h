/*
 * libblend — implicit-surface blend operators.
 * common.h: version, export macro, status codes and the error record.
 *
 * Conventions for the whole API (stated once here):
 *  - Every public name starts with `lb_` (functions, types) or `LB_` (macros,
 *    enum values).
 *  - Functions that can fail return an lb_status and take a trailing
 *    `lb_error *err`, which may be NULL. On failure err->message names the
 *    parameter, the allowed range and the value that was passed.
 *  - All buffers are owned by the caller. The library keeps no global
 *    mutable state: every function is safe to call from any thread as long as
 *    the buffers passed to it are not written concurrently.
 *  - Invalid parameters are rejected, never clamped.
 */
#ifndef LIBBLEND_COMMON_H
#define LIBBLEND_COMMON_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(LIBBLEND_BUILDING)
#define LB_API __declspec(dllexport)
#else
#define LB_API
#endif
#else
#define LB_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define LB_VERSION_MAJOR 0
#define LB_VERSION_MINOR 1
#define LB_VERSION_PATCH 0

/* Status codes. LB_OK is 0; every other value is a failure. */
typedef enum lb_status {
    LB_OK = 0,
    LB_ERR_INVALID_ARGUMENT = 1, /* a parameter is outside its documented range */
    LB_ERR_NOT_FINITE = 2,       /* an input value is NaN or infinite */
    LB_ERR_NO_MEMORY = 3,        /* an allocation failed or a size limit was hit */
    LB_ERR_INTERNAL = 4,         /* a bug in libblend: please report it */
    LB_ERR_CANCELLED = 5,        /* the caller cancelled a long run (progress callback, flag) */
    LB_ERR_IO = 6                /* a file could not be read or written */
} lb_status;

#define LB_ERROR_MESSAGE_SIZE 512

/* Filled by functions that fail. Zero-initialise it or leave it untouched:
 * the library writes it only on failure. */
typedef struct lb_error {
    lb_status status;
    char message[LB_ERROR_MESSAGE_SIZE];
} lb_error;

/* Runtime version as MAJOR*10000 + MINOR*100 + PATCH. Bindings compare it
 * with the version they were written for. */
LB_API int lb_version(void);

/* A short, static, human-readable name for a status code. Never NULL. */
LB_API const char *lb_status_string(lb_status status);

#ifdef __cplusplus
}
#endif

#endif
