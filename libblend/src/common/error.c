/* Error records, parameter validation and bounded text shared by every
 * public entry point. */
#include "internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int lb_version(void) {
    return LB_VERSION_MAJOR * 10000 + LB_VERSION_MINOR * 100 + LB_VERSION_PATCH;
}

const char *lb_status_string(lb_status status) {
    switch (status) {
    case LB_OK:
        return "ok";
    case LB_ERR_INVALID_ARGUMENT:
        return "invalid argument";
    case LB_ERR_NOT_FINITE:
        return "non-finite input";
    case LB_ERR_NO_MEMORY:
        return "out of memory or over a size limit";
    case LB_ERR_INTERNAL:
        return "internal error";
    case LB_ERR_CANCELLED:
        return "cancelled";
    case LB_ERR_IO:
        return "input/output error";
    }
    return "unknown status";
}

/* Messages are one line of text whatever went into them (file names, JSON
 * strings): control characters are written as \n, \t, \r or \xNN. */
lb_status lb__fail(lb_error *err, lb_status status, const char *fmt, ...) {
    if (err) {
        char raw[LB_ERROR_MESSAGE_SIZE];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(raw, sizeof raw, fmt, ap);
        va_end(ap);
        size_t o = 0;
        for (const unsigned char *c = (const unsigned char *)raw; *c; ++c) {
            char esc[5] = {(char)*c, 0, 0, 0, 0};
            if (*c < 0x20 || *c == 0x7f) {
                if (*c == '\n' || *c == '\t' || *c == '\r')
                    snprintf(esc, sizeof esc, "\\%c", *c == '\n' ? 'n' : *c == '\t' ? 't' : 'r');
                else
                    snprintf(esc, sizeof esc, "\\x%02x", *c);
            }
            const size_t l = strlen(esc);
            if (o + l >= sizeof err->message) break;
            memcpy(err->message + o, esc, l);
            o += l;
        }
        err->message[o] = '\0';
        err->status = status;
    }
    return status;
}

void lb__text_put(lb__text *b, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    const size_t room = b->len < b->size ? b->size - b->len : 0;
    const int n = vsnprintf(room ? b->buf + b->len : NULL, room, fmt, ap);
    va_end(ap);
    if (n > 0) b->len += (size_t)n;
}

lb_status lb__check_k(const char *fn, size_t k, size_t kmin, size_t kmax, lb_error *err) {
    if (k < kmin || k > kmax) {
        if (kmin == kmax)
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: k = %zu arguments; this operator takes exactly %zu", fn, k, kmin);
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: k = %zu arguments; allowed: %zu <= k <= %zu", fn, k, kmin, kmax);
    }
    return LB_OK;
}

lb_status lb__check_finite(const char *fn, const char *name, size_t n, const double *v,
                           lb_error *err) {
    if (!v) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: %s is NULL", fn, name);
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(v[i]))
            return lb__fail(err, LB_ERR_NOT_FINITE, "%s: %s[%zu] = %g is not finite", fn, name, i,
                            v[i]);
        if (fabs(v[i]) > LB_MAX_ABS_ARG)
            return lb__fail(err, LB_ERR_NOT_FINITE,
                            "%s: %s[%zu] = %g is beyond the supported range; allowed: |%s| <= %g",
                            fn, name, i, v[i], name, LB_MAX_ABS_ARG);
    }
    return LB_OK;
}

lb_status lb__check_range(const char *fn, const char *name, size_t n, const double *v, double lo,
                          int lo_closed, double hi, int hi_closed, const char *what,
                          lb_error *err) {
    if (!v) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: %s is NULL", fn, name);
    for (size_t i = 0; i < n; ++i) {
        const double a = v[i];
        const int ok =
            isfinite(a) && (lo_closed ? a >= lo : a > lo) && (hi_closed ? a <= hi : a < hi);
        if (!ok) {
            if (n == 1)
                return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                                "%s: %s = %g is out of range; allowed: %s", fn, name, a, what);
            return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                            "%s: %s[%zu] = %g is out of range; allowed: %s", fn, name, i, a, what);
        }
    }
    return LB_OK;
}

lb_status lb__check_r_m(const char *fn, const char *rname, const char *mname, size_t k,
                        const double *r, const double *m, double rmax, double mmin, double mmax,
                        lb_error *err) {
    const double rhi = rmax < LB_MAX_RANGE ? rmax : LB_MAX_RANGE;
    int ok = r != NULL;
    for (size_t i = 0; ok && i < k; ++i) {
        ok &= r[i] >= LB_MIN_RANGE && r[i] <= rhi;
        if (m) ok &= m[i] >= mmin && m[i] <= mmax;
    }
    if (ok) return LB_OK; /* the message is formatted only on failure: this runs per call */
    char what[64];
    snprintf(what, sizeof what, "%g <= r <= %g", LB_MIN_RANGE, rhi);
    lb_status s = lb__check_range(fn, rname, k, r, LB_MIN_RANGE, 1, rhi, 1, what, err);
    if (s || !m) return s;
    snprintf(what, sizeof what, "%g <= m <= %g", mmin, mmax);
    return lb__check_range(fn, mname, k, m, mmin, 1, mmax, 1, what, err);
}

lb_status lb__check_setop(const char *fn, lb_setop op, lb_error *err) {
    if (op != LB_UNION && op != LB_INTERSECTION && op != LB_DIFFERENCE)
        return lb__fail(err, LB_ERR_INVALID_ARGUMENT,
                        "%s: op = %d is not a set operation; allowed: LB_UNION (0), "
                        "LB_INTERSECTION (1), LB_DIFFERENCE (2)",
                        fn, (int)op);
    return LB_OK;
}

lb_status lb__check_out(const char *fn, const void *value, lb_error *err) {
    if (!value) return lb__fail(err, LB_ERR_INVALID_ARGUMENT, "%s: value (output) is NULL", fn);
    return LB_OK;
}

lb_status lb__check_p(const char *fn, size_t k, const double *p, lb_error *err) {
    return lb__check_range(fn, "p", k, p, 1.0, 0, LB_MAX_EXPONENT, 1, "1 < p <= 1000", err);
}

void lb__dual_args(lb_setop op, size_t k, const double *x, double *xt, double *sign) {
    for (size_t i = 0; i < k; ++i) {
        const double s = (op == LB_UNION) ? 1.0 : (op == LB_INTERSECTION || i == 0) ? -1.0 : 1.0;
        sign[i] = s;
        xt[i] = s * x[i];
    }
}
