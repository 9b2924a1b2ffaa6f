/* SPDX-License-Identifier: MIT */
/* A head made by code, its expressions and a warp (head.h). Every feature is a Gaussian bump in
 * the direction from the head's centre or around a point of the surface, so the surface, the
 * expressions and the warp are smooth everywhere. */
#include "head.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "mesh_groups.h"
#include "primitives.h"

static double dist2(const double a[3], const double b[3])
{
    double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

static void unit(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int c = 0; c < 3; c++) v[c] /= l;
}

static double smoothstep(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x * x * (3 - 2 * x);
}

void mk_head_surface(const double direction[3], double out[3])
{
    double dir[3] = { direction[0], direction[1], direction[2] };
    unit(dir);
    double nose[3] = { 0, -0.1, 1 }, chin[3] = { 0, -0.75, 0.66 }, eye_l[3] = { 0.3, 0.15, 0.94 },
           eye_r[3] = { -0.3, 0.15, 0.94 }, ear_l[3] = { 1, 0.05, -0.1 }, ear_r[3] = { -1, 0.05, -0.1 };
    unit(nose); unit(chin); unit(eye_l); unit(eye_r); unit(ear_l); unit(ear_r);
    double front = dir[2] > 0 ? dir[2] * dir[2] : 0;
    double r = 1 + 0.22 * exp(-dist2(dir, nose) / 0.03)              /* nose */
             + 0.06 * exp(-(dir[1] - 0.35) * (dir[1] - 0.35) / 0.01) * front  /* brow ridge */
             + 0.08 * exp(-dist2(dir, chin) / 0.05)                 /* chin */
             - 0.05 * exp(-dist2(dir, eye_l) / 0.01) - 0.05 * exp(-dist2(dir, eye_r) / 0.01)   /* eye sockets */
             + 0.03 * exp(-(dir[1] + 0.45) * (dir[1] + 0.45) / 0.004) * front * front          /* lips */
             + 0.12 * exp(-dist2(dir, ear_l) / 0.01) + 0.12 * exp(-dist2(dir, ear_r) / 0.01);  /* ears */
    out[0] = 0.8 * r * dir[0];
    out[1] = 1.0 * r * dir[1];
    out[2] = 0.9 * r * dir[2];
}

void mk_head_warp(double a, const double p[3], double out[3])
{
    double y = p[1];
    out[0] = p[0] * (1 + 0.15 * a * smoothstep((y + 0.2) / 0.6)) + 0.08 * a * y * y;  /* wider brow, curved midline */
    out[1] = y;
    out[2] = p[2] * (1 + 0.12 * a * exp(-y * y / 0.18));                               /* deeper mid-face */
}

static const char *const names[MK_HEAD_EXPRESSIONS] = { "jaw_open", "smile_left", "smile_right", "brow_raise",
                                                          "cheek_puff", "nose_wrinkle" };

const char *mk_head_expression_name(uint32_t k)
{
    return k < MK_HEAD_EXPRESSIONS ? names[k] : "";
}

/* exp(-|p - head(dir)|^2 / s2): a bump around the surface point in direction dir. */
static double around(const double p[3], double x, double y, double z, double s2)
{
    double d[3] = { x, y, z }, c[3];
    unit(d);
    mk_head_surface(d, c);
    return exp(-dist2(p, c) / s2);
}

void mk_head_expression(uint32_t k, double w, const double p[3], double out[3])
{
    double d[3] = { 0, 0, 0 };
    switch (k) {
    case 0: {  /* the lower face turns about an axis along x behind the mouth */
        double m = smoothstep((-0.25 - p[1]) / 0.25) * smoothstep((p[2] + 0.2) / 0.6), a = -0.35 * w * m;
        double q[3] = { p[0], p[1] + 0.1, p[2] + 0.2 };
        d[1] = q[1] * cos(a) - q[2] * sin(a) - q[1];
        d[2] = q[1] * sin(a) + q[2] * cos(a) - q[2];
        break;
    }
    case 1: case 2: {  /* a mouth corner up and out */
        double s = k == 1 ? 1 : -1, g = w * around(p, 0.35 * s, -0.45, 0.82, 0.03);
        d[0] = 0.05 * s * g; d[1] = 0.07 * g; d[2] = -0.02 * g;
        break;
    }
    case 3: {  /* the brows up */
        double g = w * exp(-(p[1] - 0.45) * (p[1] - 0.45) / 0.02) * smoothstep((p[2] - 0.2) / 0.4);
        d[1] = 0.08 * g; d[2] = 0.01 * g;
        break;
    }
    case 4: {  /* both cheeks out */
        double g = w * (around(p, 0.55, -0.2, 0.8, 0.04) + around(p, -0.55, -0.2, 0.8, 0.04)), n[3] = { p[0], p[1], p[2] };
        unit(n);
        for (int c = 0; c < 3; c++) d[c] = 0.09 * g * n[c];
        break;
    }
    default: {  /* the nose up */
        double g = w * around(p, 0, 0.05, 1, 0.01);
        d[1] = 0.04 * g; d[2] = -0.01 * g;
        break;
    }
    }
    for (int c = 0; c < 3; c++) out[c] = p[c] + d[c];
}

static const double marker_dirs[12][3] = { { 0, -0.1, 1 }, { 0, -0.75, 0.66 }, { 0, 0.4, 0.92 }, { 0.3, 0.15, 0.94 },
                                           { -0.3, 0.15, 0.94 }, { 0.35, -0.45, 0.82 }, { -0.35, -0.45, 0.82 },
                                           { 0.6, -0.2, 0.77 }, { -0.6, -0.2, 0.77 }, { 0, 1, 0 }, { 1, 0, 0 },
                                           { -1, 0, 0 } };

static uint32_t nearest_dir(const double *dirs, uint32_t n, const double d[3])
{
    double best = -INFINITY, u[3] = { d[0], d[1], d[2] };
    unit(u);
    uint32_t at = 0;
    for (uint32_t v = 0; v < n; v++) {
        double dot = dirs[3 * v] * u[0] + dirs[3 * v + 1] * u[1] + dirs[3 * v + 2] * u[2];
        if (dot > best) { best = dot; at = v; }
    }
    return at;
}

void mk_head_marker_pairs(const mk_raw_mesh *src, const double *sdir, mk_raw_mesh *dst, double *ddir, double warp,
                          uint32_t count, uint32_t (*pairs)[2])
{
    for (uint32_t m = 0; m < count && m < 12; m++) {
        uint32_t s = nearest_dir(sdir, src->vertex_count, marker_dirs[m]);
        uint32_t t = nearest_dir(ddir, dst->vertex_count, sdir + 3 * (size_t)s);
        double surf[3], q[3];
        memcpy(ddir + 3 * (size_t)t, sdir + 3 * (size_t)s, 3 * sizeof(double));
        mk_head_surface(ddir + 3 * (size_t)t, surf);
        mk_head_warp(warp, surf, q);
        for (int c = 0; c < 3; c++) dst->positions[3 * (size_t)t + c] = (float)q[c];
        pairs[m][0] = s;
        pairs[m][1] = t;
    }
}

/* A UV sphere: poles on y (one vertex each), rings - 1 rows of 2 rings vertices. */
static mk_raw_mesh *add_uv_sphere(mk_raw_asset *raw, const char *name, uint32_t rings)
{
    uint32_t segs = 2 * rings, nv = 2 + (rings - 1) * segs, nt = 2 * segs * (rings - 1);
    mk_raw_mesh *m = mk_raw_add_meshes(raw, 1);
    if (!m) return NULL;
    m->name = mk_arena_strdup(&raw->arena, name);
    m->vertex_count = nv;
    m->triangle_count = nt;
    m->positions = mk_arena_array(&raw->arena, 3 * (size_t)nv, sizeof(float));
    m->normals = mk_arena_array(&raw->arena, 3 * (size_t)nv, sizeof(float));
    m->triangles = mk_arena_array(&raw->arena, 3 * (size_t)nt, sizeof(uint32_t));
    m->control_point_count = nv;
    m->control_points = mk_arena_array(&raw->arena, nv, sizeof(uint32_t));
    if (!m->name || !m->positions || !m->normals || !m->triangles || !m->control_points) return NULL;
    const double pi = 3.14159265358979323846;
    float *p = m->positions;
    p[0] = 0; p[1] = 1; p[2] = 0;
    for (uint32_t r = 1; r < rings; r++)
        for (uint32_t s = 0; s < segs; s++) {
            double th = pi * r / rings, ph = 2 * pi * s / segs;
            float *q = p + 3 * (size_t)(1 + (r - 1) * segs + s);
            q[0] = (float)(sin(th) * cos(ph)); q[1] = (float)cos(th); q[2] = (float)(sin(th) * sin(ph));
        }
    p[3 * (size_t)(nv - 1)] = 0; p[3 * (size_t)(nv - 1) + 1] = -1; p[3 * (size_t)(nv - 1) + 2] = 0;
    uint32_t *t = m->triangles;
    for (uint32_t s = 0; s < segs; s++) {  /* outward: counter-clockwise seen from outside */
        uint32_t a = 1 + s, b = 1 + (s + 1) % segs;
        *t++ = 0; *t++ = b; *t++ = a;
        uint32_t c = 1 + (rings - 2) * segs + s, d = 1 + (rings - 2) * segs + (s + 1) % segs;
        *t++ = nv - 1; *t++ = c; *t++ = d;
    }
    for (uint32_t r = 1; r + 1 < rings; r++)
        for (uint32_t s = 0; s < segs; s++) {
            uint32_t a = 1 + (r - 1) * segs + s, b = 1 + (r - 1) * segs + (s + 1) % segs, c = a + segs, d = b + segs;
            *t++ = a; *t++ = b; *t++ = c;
            *t++ = b; *t++ = d; *t++ = c;
        }
    for (uint32_t v = 0; v < nv; v++) m->control_points[v] = v;
    return m;
}

/* One target of channel ch at full weight w: expression k on the unwarped head, then warped. */
static int add_expression_target(mk_raw_asset *raw, mk_raw_channel *ch, uint32_t k, double w, double warp,
                                 const double *surface, const mk_raw_mesh *m)
{
    mk_raw_target *t = mk_raw_add_targets(raw, ch, 1);
    if (!t) return 0;
    t->name = ch->name;
    t->full_weight = (float)w;
    t->indices = mk_arena_array(&raw->arena, m->vertex_count, sizeof(uint32_t));
    t->positions = mk_arena_array(&raw->arena, 3 * (size_t)m->vertex_count, sizeof(float));
    if (!t->indices || !t->positions) return 0;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        double moved[3], warped[3];
        mk_head_expression(k, w, surface + 3 * (size_t)v, moved);
        mk_head_warp(warp, moved, warped);
        float d[3];
        for (int c = 0; c < 3; c++) d[c] = (float)(warped[c] - m->positions[3 * (size_t)v + c]);
        if (fabsf(d[0]) + fabsf(d[1]) + fabsf(d[2]) < 1e-7f) continue;
        t->indices[t->count] = v;
        memcpy(t->positions + 3 * (size_t)t->count++, d, sizeof d);
    }
    return 1;
}

mk_raw_mesh *mk_raw_add_head(mk_raw_asset *raw, const char *name, uint32_t levels, int uv, double turn, double warp,
                             int expressions, double **dirs)
{
    if (dirs) *dirs = NULL;
    uint32_t mesh_index = raw->mesh_count;
    mk_raw_mesh *m = uv ? add_uv_sphere(raw, name, levels) : mk_raw_add_icosphere(raw, name, 1, levels);
    if (!m) return NULL;
    size_t n = m->vertex_count;
    double *dir = malloc(3 * n * sizeof(double)), *surface = malloc(3 * n * sizeof(double));
    if (!dir || !surface) { free(dir); free(surface); return NULL; }
    for (size_t v = 0; v < n; v++) {
        const float *p = m->positions + 3 * v;
        double d[3] = { cos(turn) * p[0] + sin(turn) * p[2], p[1], -sin(turn) * p[0] + cos(turn) * p[2] }, q[3];
        unit(d);
        memcpy(dir + 3 * v, d, sizeof d);
        mk_head_surface(d, surface + 3 * v);
        mk_head_warp(warp, surface + 3 * v, q);
        for (int c = 0; c < 3; c++) m->positions[3 * v + c] = (float)q[c];
    }
    /* area-weighted normals of the head as built */
    double *acc = calloc(3 * n, sizeof(double));
    int ok = acc != NULL;
    for (uint32_t t = 0; ok && t < m->triangle_count; t++) {
        double f[3];
        mk_face_normal(m, NULL, t, f);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) acc[3 * (size_t)m->triangles[3 * (size_t)t + k] + c] += f[c];
    }
    for (size_t v = 0; ok && v < n; v++) {
        unit(acc + 3 * v);
        for (int c = 0; c < 3; c++) m->normals[3 * v + c] = (float)acc[3 * v + c];
    }
    free(acc);
    for (uint32_t k = 0; ok && expressions && k < MK_HEAD_EXPRESSIONS; k++) {
        mk_raw_channel *ch = mk_raw_add_channels(raw, 1);
        ok = ch != NULL;
        if (!ok) break;
        ch->name = mk_arena_strdup(&raw->arena, mk_head_expression_name(k));
        ch->mesh = mesh_index;
        ok = ch->name && (k != 0 || add_expression_target(raw, ch, k, 0.5, warp, surface, m)) &&
             add_expression_target(raw, ch, k, 1, warp, surface, m);
    }
    if (ok && expressions) {
        mk_error err;
        ok = mk_raw_compute_target_normals(raw, mesh_index, 0, 1, &err) == MK_OK;
    }
    free(surface);
    if (!ok) { free(dir); return NULL; }
    if (dirs) *dirs = dir;
    else free(dir);
    return &raw->meshes[mesh_index];
}
