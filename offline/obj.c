/* SPDX-License-Identifier: MIT */
/* The one Wavefront OBJ reader of the offline tools: cages for the bakers, reference frames for
 * conformance. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "blob_io.h"
#include "obj.h"

static const char *skip_space(const char *p, const char *end)
{
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) p++;
    return p;
}

/* Three finite numbers after a "v" or "vn" keyword; returns the end, or NULL. */
static const char *read_triple(const char *q, const char *eol, double xyz[3])
{
    for (int c = 0; c < 3; c++) {
        q = skip_space(q, eol);
        char buf[64];
        size_t len = 0;
        while (q + len < eol && len < sizeof buf - 1 && q[len] != ' ' && q[len] != '\t' && q[len] != '\r') len++;
        memcpy(buf, q, len);
        buf[len] = 0;
        char *stop;
        xyz[c] = strtod(buf, &stop);
        if (len == 0 || *stop || !isfinite(xyz[c])) return NULL;
        q += len;
    }
    return q;
}

/* OBJ is line based: "v x y z [w]", "vn x y z" and "f i[/t[/n]] j ... " (1-based, negative =
 * relative). Two passes over the text: count, then fill. Everything else is ignored. */
mk_result mk_obj_read(const char *path, mk_arena *arena, mk_obj *out, mk_error *err)
{
    memset(out, 0, sizeof *out);
    void *data;
    size_t size;
    mk_result r = mk_read_file(arena, path, (size_t)1 << 30, &data, &size, err);
    if (r != MK_OK) return r;
    const char *text = data, *end = text + size;
    size_t nv = 0, nt = 0, nn = 0;
    double *v = NULL, *n = NULL;
    uint32_t *t = NULL;
    for (int pass = 0; pass < 2; pass++) {
        size_t iv = 0, it = 0, in = 0, line_no = 0;
        for (const char *p = text; p < end;) {
            const char *eol = memchr(p, '\n', (size_t)(end - p));
            if (!eol) eol = end;
            line_no++;
            const char *q = skip_space(p, eol);
            int is_normal = eol - q >= 3 && q[0] == 'v' && q[1] == 'n' && (q[2] == ' ' || q[2] == '\t');
            if ((eol - q >= 2 && q[0] == 'v' && (q[1] == ' ' || q[1] == '\t')) || is_normal) {
                double xyz[3];
                if (!read_triple(q + (is_normal ? 3 : 2), eol, xyz))
                    return mk_error_set(err, MK_ERROR_PARSE, (uint64_t)(q - text),
                                        "%s:%zu: %s needs 3 finite coordinates", path, line_no,
                                        is_normal ? "a normal" : "a vertex");
                if (is_normal) {
                    if (pass == 1 && n)
                        for (int c = 0; c < 3; c++) n[3 * in + (size_t)c] = xyz[c];
                    in++;
                } else {
                    if (pass == 1)
                        for (int c = 0; c < 3; c++) v[3 * iv + (size_t)c] = xyz[c];
                    iv++;
                }
            } else if (eol - q >= 2 && q[0] == 'f' && (q[1] == ' ' || q[1] == '\t')) {
                q += 2;
                uint32_t first = 0, prev = 0;
                int corners = 0;
                for (;;) {
                    q = skip_space(q, eol);
                    if (q >= eol) break;
                    char buf[32];
                    size_t len = 0;
                    while (q + len < eol && len < sizeof buf - 1 && q[len] != ' ' && q[len] != '\t' && q[len] != '\r' &&
                           q[len] != '/')
                        len++;
                    memcpy(buf, q, len);
                    buf[len] = 0;
                    char *stop;
                    errno = 0;
                    long idx = strtol(buf, &stop, 10);
                    if (len == 0 || *stop || errno)
                        return mk_error_set(err, MK_ERROR_PARSE, (uint64_t)(q - text), "%s:%zu: bad face index", path,
                                            line_no);
                    /* skip "/t/n" */
                    while (q < eol && *q != ' ' && *q != '\t' && *q != '\r') q++;
                    long resolved = idx > 0 ? idx - 1 : (long)iv + idx;
                    if (idx == 0 || resolved < 0 || (pass == 1 && (size_t)resolved >= nv) ||
                        (pass == 0 && (size_t)resolved >= iv))
                        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s:%zu: face index %ld is out of range",
                                            path, line_no, idx);
                    uint32_t cur = (uint32_t)resolved;
                    if (corners == 0)
                        first = cur;
                    else if (corners >= 2) {
                        /* fan triangulation */
                        if (pass == 1) {
                            t[3 * it] = first;
                            t[3 * it + 1] = prev;
                            t[3 * it + 2] = cur;
                        }
                        it++;
                    }
                    prev = cur;
                    corners++;
                }
                if (corners < 3)
                    return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s:%zu: face with fewer than 3 corners", path,
                                        line_no);
            }
            p = eol < end ? eol + 1 : end;
        }
        if (pass == 0) {
            nv = iv;
            nt = it;
            nn = in;
            if (nv > UINT32_MAX / 4 || nt > UINT32_MAX / 4)
                return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: too many elements", path);
            v = mk_arena_array(arena, nv ? 3 * nv : 1, sizeof(double));
            t = mk_arena_array(arena, nt ? 3 * nt : 1, sizeof(uint32_t));
            /* Normals count only when there is one per vertex (as 'morphkit play' writes them). */
            n = nn == nv && nv ? mk_arena_array(arena, 3 * nn, sizeof(double)) : NULL;
            if (!v || !t || (nn == nv && nv && !n)) return mk_error_oom(err, "OBJ");
        }
    }
    mk_arena_release(arena, data);
    out->positions = v;
    out->normals = n;
    out->vertex_count = (uint32_t)nv;
    out->triangles = t;
    out->triangle_count = (uint32_t)nt;
    return MK_OK;
}
