/* JSON checks shared by the scene parser and blendtool's job files
 * (json_check.h). */
#include "json_check.h"

#include <stdio.h>
#include <string.h>

/* ---- JSON paths ---- */

void lb__jpath_set(lb__jpath *p, const char *root) {
    const int n = snprintf(p->s, sizeof p->s, "%s", root);
    p->len = n > 0 && (size_t)n < sizeof p->s ? (size_t)n : strlen(p->s);
}

/* after an snprintf of n at old: the new length, or where the cut text ends */
static size_t jpath_end(const lb__jpath *p, size_t old, int n) {
    return n > 0 && (size_t)n < sizeof p->s - old ? old + (size_t)n : strlen(p->s);
}

size_t lb__jpath_key(lb__jpath *p, const char *key) {
    const size_t old = p->len;
    p->len = jpath_end(p, old, snprintf(p->s + old, sizeof p->s - old, ".%s", key));
    return old;
}

size_t lb__jpath_index(lb__jpath *p, size_t i) {
    const size_t old = p->len;
    p->len = jpath_end(p, old, snprintf(p->s + old, sizeof p->s - old, "[%zu]", i));
    return old;
}

void lb__jpath_pop(lb__jpath *p, size_t old) {
    p->len = old;
    p->s[old] = '\0';
}

/* ---- values and keys ---- */

const char *lb__json_kind(const cJSON *j) {
    if (!j) return "nothing";
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an invalid value";
}

int lb__json_keys(const cJSON *obj, const char *const *allowed, const cJSON **bad) {
    for (const cJSON *it = obj->child; it; it = it->next) {
        int ok = 0;
        for (const char *const *a = allowed; *a && !ok; ++a) ok = strcmp(*a, it->string) == 0;
        *bad = it;
        if (!ok) return 1;
        for (const cJSON *o = obj->child; o != it; o = o->next)
            if (strcmp(o->string, it->string) == 0) return 2;
    }
    *bad = NULL;
    return 0;
}

/* ---- RFC 8259 strictness: one pass over the text ---- */

typedef struct jscan {
    const unsigned char *t;
    size_t n, i;
    const char *what; /* the first violation, or NULL */
    size_t at;        /* its offset */
} jscan;

static int fail_at(jscan *S, size_t at, const char *what) {
    if (!S->what) {
        S->what = what;
        S->at = at;
    }
    return 0;
}

static void ws(jscan *S) {
    while (S->i < S->n &&
           (S->t[S->i] == ' ' || S->t[S->i] == '\t' || S->t[S->i] == '\n' || S->t[S->i] == '\r'))
        ++S->i;
}

static int digit(jscan *S) {
    return S->i < S->n && S->t[S->i] >= '0' && S->t[S->i] <= '9';
}

/* -? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE] [+-]? [0-9]+)? */
static int number(jscan *S) {
    const size_t at = S->i;
    if (S->t[S->i] == '-') ++S->i;
    if (!digit(S)) return fail_at(S, at, "a number needs a digit after its sign");
    if (S->t[S->i] == '0') {
        ++S->i;
        if (digit(S)) return fail_at(S, at, "a number with a leading zero");
    } else {
        while (digit(S)) ++S->i;
    }
    if (S->i < S->n && S->t[S->i] == '.') {
        ++S->i;
        if (!digit(S)) return fail_at(S, at, "a decimal point without digits after it");
        while (digit(S)) ++S->i;
    }
    if (S->i < S->n && (S->t[S->i] == 'e' || S->t[S->i] == 'E')) {
        ++S->i;
        if (S->i < S->n && (S->t[S->i] == '+' || S->t[S->i] == '-')) ++S->i;
        if (!digit(S)) return fail_at(S, at, "an exponent without digits");
        while (digit(S)) ++S->i;
    }
    return 1;
}

static int hex4(jscan *S, unsigned *u) {
    *u = 0;
    for (int k = 0; k < 4; ++k, ++S->i) {
        if (S->i >= S->n) return 0;
        const unsigned char c = S->t[S->i];
        const int v = c >= '0' && c <= '9'   ? c - '0'
                      : c >= 'a' && c <= 'f' ? c - 'a' + 10
                      : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                             : -1;
        if (v < 0) return 0;
        *u = *u * 16 + (unsigned)v;
    }
    return 1;
}

/* one UTF-8 sequence at S->i (RFC 3629: shortest form, no surrogates, at
 * most U+10FFFF) */
static int utf8(jscan *S) {
    const unsigned char c = S->t[S->i];
    size_t len;
    unsigned cp, min;
    if (c < 0x80) {
        ++S->i;
        return 1;
    } else if ((c & 0xE0) == 0xC0) {
        len = 2, cp = c & 0x1Fu, min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
        len = 3, cp = c & 0x0Fu, min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
        len = 4, cp = c & 0x07u, min = 0x10000;
    } else {
        return fail_at(S, S->i, "a byte that is not UTF-8");
    }
    if (S->i + len > S->n) return fail_at(S, S->i, "a UTF-8 sequence cut short");
    for (size_t k = 1; k < len; ++k) {
        const unsigned char d = S->t[S->i + k];
        if ((d & 0xC0) != 0x80) return fail_at(S, S->i, "a byte that is not UTF-8");
        cp = cp << 6 | (d & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
        return fail_at(S, S->i, "a byte sequence that is not UTF-8");
    S->i += len;
    return 1;
}

static int string(jscan *S) {
    ++S->i; /* the opening quote */
    while (S->i < S->n) {
        const unsigned char c = S->t[S->i];
        if (c == '"') {
            ++S->i;
            return 1;
        }
        if (c < 0x20) return fail_at(S, S->i, "a control character in a string (escape it)");
        if (c != '\\') {
            if (!utf8(S)) return 0;
            continue;
        }
        const size_t at = S->i++;
        if (S->i >= S->n) break;
        const unsigned char e = S->t[S->i++];
        if (strchr("\"\\/bfnrt", e) && e) continue;
        if (e != 'u') return fail_at(S, at, "an unknown escape in a string");
        unsigned u, v;
        if (!hex4(S, &u)) return fail_at(S, at, "\\u needs four hex digits");
        if (u == 0) return fail_at(S, at, "\\u0000 is not allowed");
        if (u >= 0xDC00 && u <= 0xDFFF) return fail_at(S, at, "a lone UTF-16 low surrogate");
        if (u >= 0xD800 && u <= 0xDBFF) {
            if (!(S->i + 1 < S->n && S->t[S->i] == '\\' && S->t[S->i + 1] == 'u'))
                return fail_at(S, at, "a lone UTF-16 high surrogate");
            S->i += 2;
            if (!hex4(S, &v) || v < 0xDC00 || v > 0xDFFF)
                return fail_at(S, at, "a UTF-16 high surrogate without its low one");
        }
    }
    return fail_at(S, S->n, "a string without its closing quote");
}

static int literal(jscan *S, const char *word) {
    const size_t len = strlen(word);
    if (S->n - S->i < len || memcmp(S->t + S->i, word, len) != 0)
        return fail_at(S, S->i, "an unknown token");
    S->i += len;
    return 1;
}

static int value(jscan *S);

/* members or elements up to close, after the opening bracket */
static int members(jscan *S, int object) {
    const unsigned char close = object ? '}' : ']';
    ++S->i;
    ws(S);
    if (S->i < S->n && S->t[S->i] == close) {
        ++S->i;
        return 1;
    }
    for (;;) {
        if (object) {
            if (S->i >= S->n || S->t[S->i] != '"') return fail_at(S, S->i, "a key expected");
            if (!string(S)) return 0;
            ws(S);
            if (S->i >= S->n || S->t[S->i] != ':') return fail_at(S, S->i, "':' expected");
            ++S->i;
        }
        if (!value(S)) return 0;
        ws(S);
        if (S->i < S->n && S->t[S->i] == ',') {
            ++S->i;
            ws(S);
            continue;
        }
        if (S->i < S->n && S->t[S->i] == close) {
            ++S->i;
            return 1;
        }
        return fail_at(S, S->i, object ? "',' or '}' expected" : "',' or ']' expected");
    }
}

static int value(jscan *S) {
    ws(S);
    if (S->i >= S->n) return fail_at(S, S->i, "a value expected at the end of the input");
    switch (S->t[S->i]) {
    case '{':
        return members(S, 1);
    case '[':
        return members(S, 0);
    case '"':
        return string(S);
    case 't':
        return literal(S, "true");
    case 'f':
        return literal(S, "false");
    case 'n':
        return literal(S, "null");
    default:
        if (S->t[S->i] == '-' || digit(S)) return number(S);
        return fail_at(S, S->i, "an unknown token");
    }
}

const char *lb__json_strictness(const char *text, size_t length, size_t *line, size_t *col,
                                char near[16]) {
    jscan S = {(const unsigned char *)text, length, 0, NULL, 0};
    if (value(&S)) {
        ws(&S);
        if (S.i < S.n)
            fail_at(&S, S.i,
                    S.t[S.i] ? "text after the end of the document" : "a NUL byte in the text");
    }
    *line = *col = 1;
    near[0] = '\0';
    if (!S.what) return NULL;
    for (size_t i = 0; i < S.at && i < length; ++i) {
        if (text[i] == '\n') {
            ++*line;
            *col = 1;
        } else {
            ++*col;
        }
    }
    size_t nl = 0;
    for (size_t i = S.at; i < length && nl < 8; ++i)
        near[nl++] = text[i] >= 32 && text[i] < 127 ? text[i] : '?';
    near[nl] = '\0';
    return S.what;
}
