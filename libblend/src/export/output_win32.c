/* Output files on Windows (libblend/output.h): the bytes go to a hidden
 * temporary file ".NAME.lbtmp.PID.XXXXXXXXXXXX" in the target's folder,
 * moved over the target by lb_output_commit with MoveFileExW
 * (MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH): a reader sees the
 * old file or the new one, never a partial one. Paths are UTF-8 and reach
 * Windows through its wide API, so non-ASCII names work whatever the code
 * page. A symbolic link or junction to a file is followed (the file it leads
 * to is replaced: GetFinalPathNameByHandleW); a character device (NUL, CON,
 * a COM port) or a pipe is written directly; a folder is refused. Temporary
 * files whose process is gone are removed by the next open of the same
 * path, as on POSIX. New files get the folder's inherited permissions. */
#include "output_internal.h"
#include "../common/platform.h"

#include <windows.h>

#include <errno.h>
#include <fcntl.h>
#include <io.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>

static const char FN[] = "lb_output";

enum { OUT_NAMED = 1, OUT_DIRECT };

struct lb_output {
    lb__output_head h; /* h.temp: wtemp in UTF-8 */
    int how;
    wchar_t *wpath; /* the target, links resolved */
    wchar_t *wtemp; /* OUT_NAMED: the temporary file */
    char *path;     /* the path as given, for messages */
};

static void output_free(lb_output *o) {
    if (!o) return;
    free(o->wpath);
    free(o->wtemp);
    free(o->h.temp);
    free(o->path);
    free(o);
}

/* Windows' text for an error code, without its line break. */
static const char *win_message(DWORD code, char *buf, size_t size) {
    DWORD n = FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, NULL, code,
                             0, buf, (DWORD)size, NULL);
    while (n > 0 && (buf[n - 1] == '\n' || buf[n - 1] == '\r' || buf[n - 1] == '.')) --n;
    if (n == 0)
        snprintf(buf, size, "Windows error %lu", (unsigned long)code);
    else
        buf[n] = '\0';
    return buf;
}

/* A wide string back to a new UTF-8 string, or NULL. */
static char *narrow(const wchar_t *w) {
    const int n = WideCharToMultiByte(CP_UTF8, 0, w, -1, NULL, 0, NULL, NULL);
    if (n <= 0) return NULL;
    char *s = malloc((size_t)n);
    if (s) WideCharToMultiByte(CP_UTF8, 0, w, -1, s, n, NULL, NULL);
    return s;
}

static wchar_t *wdup(const wchar_t *w, size_t n) {
    wchar_t *o = malloc((n + 1) * sizeof *o);
    if (o) {
        memcpy(o, w, n * sizeof *o);
        o[n] = L'\0';
    }
    return o;
}

/* The folder part of a path (up to its last separator; "." when none) and
 * the name after it. */
static int split(const wchar_t *p, wchar_t **dir, wchar_t **base) {
    const wchar_t *s = NULL;
    for (const wchar_t *c = p; *c; ++c)
        if (*c == L'\\' || *c == L'/' || (*c == L':' && c == p + 1)) s = c;
    *dir = s ? wdup(p, (size_t)(s - p) + (s == p || *s == L':' ? 1 : 0)) : wdup(L".", 1);
    *base = wdup(s ? s + 1 : p, wcslen(s ? s + 1 : p));
    return *dir && *base;
}

/* The temporary file's name: ".NAME.lbtmp." + process id + "." + 12 hex
 * digits, in the target's folder. */
static int temp_name(const lb_output *o, const wchar_t *dir, const wchar_t *base, unsigned attempt,
                     wchar_t *buf, size_t size) {
    LARGE_INTEGER t;
    QueryPerformanceCounter(&t);
    uint64_t h = (uint64_t)t.QuadPart * 0x9E3779B97F4A7C15ull ^ (uint64_t)(uintptr_t)o ^
                 ((uint64_t)attempt << 40) ^ (uint64_t)GetTickCount64();
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    const int w =
        swprintf(buf, size, L"%ls\\.%ls.lbtmp.%lu.%012llx", dir, base,
                 (unsigned long)GetCurrentProcessId(), (unsigned long long)(h & 0xffffffffffffull));
    return w > 0 && (size_t)w < size;
}

/* Remove temporary files of the same output left by processes that are
 * gone (killed while writing). */
static void remove_stale(const wchar_t *dir, const wchar_t *base) {
    wchar_t pattern[MAX_PATH * 4], prefix[MAX_PATH * 2];
    const int pl = swprintf(prefix, sizeof prefix / sizeof *prefix, L".%ls.lbtmp.", base);
    if (pl <= 0 ||
        swprintf(pattern, sizeof pattern / sizeof *pattern, L"%ls\\%ls*", dir, prefix) <= 0)
        return;
    WIN32_FIND_DATAW fd;
    HANDLE fh = FindFirstFileW(pattern, &fd);
    if (fh == INVALID_HANDLE_VALUE) return;
    do {
        wchar_t *end = NULL;
        const unsigned long pid = wcstoul(fd.cFileName + pl, &end, 10);
        if (pid == 0 || !end || *end != L'.') continue;
        HANDLE ph = OpenProcess(PROCESS_QUERY_LIMITED_INFORMATION, FALSE, (DWORD)pid);
        int gone = ph == NULL && GetLastError() == ERROR_INVALID_PARAMETER;
        if (ph) {
            DWORD code = 0;
            gone = GetExitCodeProcess(ph, &code) && code != STILL_ACTIVE;
            CloseHandle(ph);
        }
        if (!gone) continue; /* its writer may be alive */
        wchar_t full[MAX_PATH * 4];
        if (swprintf(full, sizeof full / sizeof *full, L"%ls\\%ls", dir, fd.cFileName) > 0)
            DeleteFileW(full);
    } while (FindNextFileW(fh, &fd));
    FindClose(fh);
}

/* What is at wp: 0 nothing, 1 a file (its final path in *final), 2 a
 * device or pipe, 3 a folder; -1 on another error (code in *e). */
static int look(const wchar_t *wp, wchar_t **final, DWORD *e) {
    HANDLE h = CreateFileW(wp, FILE_READ_ATTRIBUTES,
                           FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, NULL,
                           OPEN_EXISTING, FILE_FLAG_BACKUP_SEMANTICS, NULL);
    if (h == INVALID_HANDLE_VALUE) {
        *e = GetLastError();
        return *e == ERROR_FILE_NOT_FOUND ? 0 : -1;
    }
    int kind = 1;
    const DWORD type = GetFileType(h);
    BY_HANDLE_FILE_INFORMATION info;
    if (type == FILE_TYPE_CHAR || type == FILE_TYPE_PIPE) {
        kind = 2;
    } else if (GetFileInformationByHandle(h, &info) &&
               (info.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY)) {
        kind = 3;
    } else {
        const DWORD n = GetFinalPathNameByHandleW(h, NULL, 0, FILE_NAME_NORMALIZED);
        wchar_t *buf = n ? malloc((n + 1) * sizeof *buf) : NULL;
        if (buf && GetFinalPathNameByHandleW(h, buf, n + 1, FILE_NAME_NORMALIZED) > 0) {
            *final = buf;
        } else {
            free(buf);
            *final = NULL; /* not resolvable (some network shares): the path as given */
        }
    }
    CloseHandle(h);
    return kind;
}

lb_status lb_output_open(const char *path, lb_output **out, lb_error *err) {
    if (!out) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s_open: out is NULL", FN);
    *out = NULL;
    if (!path || !*path)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s_open: no output path given; allowed: a file path", FN);
    char msg[256];
    wchar_t *wp = lb__wide(path);
    if (!wp)
        return errno == EILSEQ
                   ? lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                              "%s: the path is not UTF-8; allowed: a UTF-8 file path", path)
                   : lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    lb_output *o = calloc(1, sizeof *o);
    if (!o || !(o->path = malloc(strlen(path) + 1))) {
        free(wp);
        output_free(o);
        return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
    }
    memcpy(o->path, path, strlen(path) + 1);
    wchar_t *final = NULL;
    DWORD e = 0;
    const int kind = look(wp, &final, &e);
    if (kind < 0 || kind == 3) {
        free(wp);
        output_free(o);
        return kind == 3 ? lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                    "%s: is a folder; allowed: a file path", path)
                         : lb__fail(err, LB_ERR_IO, "%s: cannot look at the output path (%s)", path,
                                    win_message(e, msg, sizeof msg));
    }
    HANDLE h = INVALID_HANDLE_VALUE;
    if (kind == 2) {
        o->how = OUT_DIRECT;
        o->wpath = wp;
        h = CreateFileW(wp, GENERIC_WRITE, FILE_SHARE_READ | FILE_SHARE_WRITE, NULL, OPEN_EXISTING,
                        0, NULL);
        e = GetLastError();
    } else {
        o->how = OUT_NAMED;
        if (final) {
            free(wp);
            wp = final;
        }
        o->wpath = wp;
        wchar_t *dir = NULL, *base = NULL;
        if (!split(wp, &dir, &base)) {
            free(dir);
            free(base);
            output_free(o);
            return lb__fail(err, LB_ERR_NO_MEMORY, "%s: out of memory", FN);
        }
        remove_stale(dir, base);
        wchar_t name[MAX_PATH * 4];
        e = ERROR_FILENAME_EXCED_RANGE;
        for (unsigned attempt = 0; attempt < 64; ++attempt) {
            if (!temp_name(o, dir, base, attempt, name, sizeof name / sizeof *name)) break;
            h = CreateFileW(name, GENERIC_WRITE, FILE_SHARE_READ, NULL, CREATE_NEW,
                            FILE_ATTRIBUTE_HIDDEN, NULL);
            if (h != INVALID_HANDLE_VALUE) {
                o->wtemp = wdup(name, wcslen(name));
                o->h.temp = narrow(name);
                if (!o->wtemp || !o->h.temp) {
                    CloseHandle(h);
                    DeleteFileW(name);
                    h = INVALID_HANDLE_VALUE;
                    e = ERROR_NOT_ENOUGH_MEMORY;
                }
                break;
            }
            e = GetLastError();
            if (e != ERROR_FILE_EXISTS && e != ERROR_ALREADY_EXISTS) break;
        }
        free(dir);
        free(base);
    }
    FILE *f = NULL;
    if (h != INVALID_HANDLE_VALUE) {
        const int fd = _open_osfhandle((intptr_t)h, _O_WRONLY | _O_BINARY);
        f = fd >= 0 ? _fdopen(fd, "wb") : NULL;
        if (!f) {
            if (fd >= 0)
                _close(fd);
            else
                CloseHandle(h);
            e = ERROR_TOO_MANY_OPEN_FILES;
        }
    }
    if (!f) {
        if (o->wtemp) DeleteFileW(o->wtemp);
        output_free(o);
        return lb__output_open_failed(err, path, win_message(e, msg, sizeof msg));
    }
    o->h.f = f;
    *out = o;
    return LB_OK;
}

lb_status lb_output_commit(lb_output *o, lb_error *err) {
    if (!o) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s_commit: output is NULL", FN);
    int ok = fflush(o->h.f) == 0 && !ferror(o->h.f);
    DWORD e = ok ? 0 : ERROR_WRITE_FAULT;
    if (fclose(o->h.f) != 0 && ok) {
        ok = 0;
        e = ERROR_WRITE_FAULT;
    }
    if (ok && o->how == OUT_NAMED) {
        /* the temporary file was hidden; what replaces the target is not */
        SetFileAttributesW(o->wtemp, FILE_ATTRIBUTE_NORMAL);
        ok = MoveFileExW(o->wtemp, o->wpath, MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH);
        if (!ok) e = GetLastError();
    }
    if (!ok && o->wtemp) DeleteFileW(o->wtemp);
    lb_status s = LB_OK;
    if (!ok) {
        char msg[256];
        s = lb__output_write_failed(err, o->path, win_message(e, msg, sizeof msg),
                                    o->how == OUT_DIRECT);
    }
    output_free(o);
    return s;
}

void lb_output_discard(lb_output *o) {
    if (!o) return;
    fclose(o->h.f);
    if (o->wtemp) DeleteFileW(o->wtemp);
    output_free(o);
}
