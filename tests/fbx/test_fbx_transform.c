/* SPDX-License-Identifier: MIT */
/* FBX rest transforms against matrices built here, independently of importer/fbx/fbx_transform.c,
 * straight from the FBX SDK's transform formula (column vectors, double precision):
 *
 *   Local = T * Roff * Rp * Rpre * R * Rpost^-1 * Rp^-1 * Soff * Sp * S * Sp^-1
 *   World = ParentWorld * Local          (InheritType 1, RSrs, the default)
 *   mesh world = World * Tg * Rg * Sg    (the geometric transform moves the geometry only)
 *
 * T, R, S: Lcl Translation / Rotation / Scaling; Roff, Rp: RotationOffset / RotationPivot;
 * Soff, Sp: ScalingOffset / ScalingPivot; Rpre, Rpost: PreRotation / PostRotation; Tg, Rg, Sg:
 * GeometricTranslation / Rotation / Scaling. R is the Euler rotation in RotationOrder (0 XYZ,
 * 1 XZY, 2 YZX, 3 YXZ, 4 ZXY, 5 ZYX: the first letter is applied first, so XYZ is
 * Rz * Ry * Rx); Rpre, Rpost and Rg are always XYZ. Rpost^-1 is built as the reversed product
 * of the negated axis rotations, not as a transpose. Angles are degrees.
 *
 * Every case uses three non-zero angles, so the six rotation orders give six different
 * matrices (checked), and compares the imported mesh's `world` (float) with the expected
 * double matrix to 1e-6 relative to its largest entry. Fixtures come from the test writer, in
 * binary and ASCII. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "fbx_test_util.h"
#include "fbx_writer.h"

/* ---- the formula, written out ---- */

typedef struct xform {
    double t[3], r[3], s[3];         /* s: 1,1,1 when all zero (as the writer) */
    double pre[3], post[3], roff[3], rp[3], soff[3], sp[3];
    double gt[3], gr[3], gs[3];      /* gs: 1,1,1 when all zero */
    int order;
} xform;

#define DEGREES (3.14159265358979323846 / 180.0)

static const char *const order_names[6] = { "XYZ", "XZY", "YZX", "YXZ", "ZXY", "ZYX" };

static void identity(double m[16])
{
    memset(m, 0, 16 * sizeof(double));
    m[0] = m[5] = m[10] = m[15] = 1;
}

/* out = a * b (column-major, m[col * 4 + row]); out may alias a or b. */
static void mul(double out[16], const double a[16], const double b[16])
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double v = 0;
            for (int k = 0; k < 4; k++) v += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = v;
        }
    memcpy(out, r, sizeof r);
}

static void then(double m[16], const double b[16]) { mul(m, m, b); }

static void translate(double m[16], double x, double y, double z)
{
    identity(m);
    m[12] = x;
    m[13] = y;
    m[14] = z;
}

static void scale(double m[16], double x, double y, double z)
{
    identity(m);
    m[0] = x;
    m[5] = y;
    m[10] = z;
}

/* Rotation by `deg` degrees about axis 'X', 'Y' or 'Z' (right-handed, column vectors). */
static void axis(double m[16], char a, double deg)
{
    double c = cos(deg * DEGREES), s = sin(deg * DEGREES);
    identity(m);
    if (a == 'X') { m[5] = c; m[9] = -s; m[6] = s; m[10] = c; }        /* [1 0 0; 0 c -s; 0 s c] */
    else if (a == 'Y') { m[0] = c; m[8] = s; m[2] = -s; m[10] = c; }   /* [c 0 s; 0 1 0; -s 0 c] */
    else { m[0] = c; m[4] = -s; m[1] = s; m[5] = c; }                  /* [c -s 0; s c 0; 0 0 1] */
}

static double angle_of(const double deg[3], char a) { return deg[a - 'X']; }

/* Euler rotation, letters in application order: "ZXY" = Ry * Rx * Rz. */
static void euler(double m[16], const double deg[3], const char *order)
{
    double r[16];
    identity(m);
    for (int k = 0; k < 3; k++) {
        axis(r, order[k], angle_of(deg, order[k]));
        mul(m, r, m);
    }
}

/* Its inverse, undoing the last rotation first: "ZXY"^-1 = Rz(-z) * Rx(-x) * Ry(-y). */
static void euler_inverse(double m[16], const double deg[3], const char *order)
{
    double r[16];
    identity(m);
    for (int k = 0; k < 3; k++) {
        axis(r, order[k], -angle_of(deg, order[k]));
        then(m, r);
    }
}

static int all_zero(const double v[3]) { return v[0] == 0 && v[1] == 0 && v[2] == 0; }

/* Local = T * Roff * Rp * Rpre * R * Rpost^-1 * Rp^-1 * Soff * Sp * S * Sp^-1 */
static void expected_local(const xform *x, double m[16])
{
    double f[16];
    const double one[3] = { 1, 1, 1 };
    const double *s = all_zero(x->s) ? one : x->s;
    translate(m, x->t[0], x->t[1], x->t[2]);
    translate(f, x->roff[0], x->roff[1], x->roff[2]); then(m, f);
    translate(f, x->rp[0], x->rp[1], x->rp[2]); then(m, f);
    euler(f, x->pre, "XYZ"); then(m, f);
    euler(f, x->r, order_names[x->order]); then(m, f);
    euler_inverse(f, x->post, "XYZ"); then(m, f);
    translate(f, -x->rp[0], -x->rp[1], -x->rp[2]); then(m, f);
    translate(f, x->soff[0], x->soff[1], x->soff[2]); then(m, f);
    translate(f, x->sp[0], x->sp[1], x->sp[2]); then(m, f);
    scale(f, s[0], s[1], s[2]); then(m, f);
    translate(f, -x->sp[0], -x->sp[1], -x->sp[2]); then(m, f);
}

/* Tg * Rg * Sg */
static void expected_geometric(const xform *x, double m[16])
{
    double f[16];
    const double one[3] = { 1, 1, 1 };
    const double *gs = all_zero(x->gs) ? one : x->gs;
    translate(m, x->gt[0], x->gt[1], x->gt[2]);
    euler(f, x->gr, "XYZ"); then(m, f);
    scale(f, gs[0], gs[1], gs[2]); then(m, f);
}

static double max_abs(const double m[16])
{
    double v = 0;
    for (int i = 0; i < 16; i++) v = fmax(v, fabs(m[i]));
    return v;
}

static double max_diff(const double a[16], const double b[16])
{
    double v = 0;
    for (int i = 0; i < 16; i++) v = fmax(v, fabs(a[i] - b[i]));
    return v;
}

/* ---- fixtures ---- */

static const double tri_points[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
static const int32_t tri_index[3] = { 0, 1, ~2 };

static void to_mesh(const xform *x, const char *name, int parent, fbxw_mesh *m)
{
    memset(m, 0, sizeof *m);
    m->name = name;
    m->control_point_count = 3;
    m->control_points = tri_points;
    m->polygon_vertex_count = 3;
    m->polygon_vertex_index = tri_index;
    m->parent = parent;
    memcpy(m->translation, x->t, sizeof x->t);
    memcpy(m->rotation, x->r, sizeof x->r);
    memcpy(m->scaling, x->s, sizeof x->s);
    memcpy(m->pre_rotation, x->pre, sizeof x->pre);
    memcpy(m->post_rotation, x->post, sizeof x->post);
    memcpy(m->rotation_offset, x->roff, sizeof x->roff);
    memcpy(m->rotation_pivot, x->rp, sizeof x->rp);
    memcpy(m->scaling_offset, x->soff, sizeof x->soff);
    memcpy(m->scaling_pivot, x->sp, sizeof x->sp);
    memcpy(m->geometric_translation, x->gt, sizeof x->gt);
    memcpy(m->geometric_rotation, x->gr, sizeof x->gr);
    memcpy(m->geometric_scaling, x->gs, sizeof x->gs);
    m->rotation_order = x->order;
}

/* Writes the meshes (binary 7500 or ASCII 7400) and imports them; 0 on success. */
static int import_meshes(const fbxw_mesh *meshes, uint32_t count, int binary, mk_raw_asset *raw)
{
    fbxw_scene scene;
    memset(&scene, 0, sizeof scene);
    scene.version = binary ? 7500 : 7400;
    scene.binary = binary;
    scene.mesh_count = count;
    scene.meshes = meshes;
    unsigned char *data = NULL;
    size_t size = 0;
    if (fbxw_write(&scene, &data, &size) != 0) {
        CHECK_MSG(0, "writer failed");
        mk_raw_init(raw, NULL);
        return 1;
    }
    mk_error err;
    mk_result r = ft_import(data, size, NULL, raw, &err);
    free(data);
    CHECK_MSG(r == MK_OK, "import: %s", err.message);
    return r == MK_OK ? 0 : 1;
}

/* The imported world of mesh `name` equals `expect` to 1e-6 relative. */
static void check_world(const mk_raw_asset *raw, const char *name, const double expect[16], const char *label)
{
    int32_t k = ft_find_mesh(raw, name);
    CHECK_MSG(k >= 0, "%s: no mesh '%s'", label, name);
    if (k < 0) return;
    double got[16];
    for (int i = 0; i < 16; i++) got[i] = raw->meshes[k].world[i];
    double tol = 1e-6 * fmax(1.0, max_abs(expect)), d = max_diff(got, expect);
    CHECK_MSG(d <= tol, "%s: mesh '%s' world differs by %.3g (tolerance %.3g)", label, name, d, tol);
    if (d > tol)
        for (int row = 0; row < 4; row++)
            fprintf(stderr, "    got [% .6f % .6f % .6f % .6f]   expected [% .6f % .6f % .6f % .6f]\n", got[row], got[4 + row],
                    got[8 + row], got[12 + row], expect[row], expect[4 + row], expect[8 + row], expect[12 + row]);
}

/* One mesh with transform x, both encodings: world = Local * Geometric. */
static void check_single(const xform *x, const char *label)
{
    double local[16], geo[16], expect[16];
    expected_local(x, local);
    expected_geometric(x, geo);
    mul(expect, local, geo);
    for (int binary = 0; binary < 2; binary++) {
        fbxw_mesh m;
        to_mesh(x, "M", -1, &m);
        mk_raw_asset raw;
        char what[160];
        snprintf(what, sizeof what, "%s (%s)", label, binary ? "binary" : "ASCII");
        if (import_meshes(&m, 1, binary, &raw) == 0) check_world(&raw, "M", expect, what);
        mk_raw_free(&raw);
    }
}

/* ---- cases ---- */

/* The six orders with rotation (30, -50, 70): six different matrices, each imported exactly. */
static void test_rotation_orders(void)
{
    double m[6][16];
    for (int o = 0; o < 6; o++) {
        xform x;
        memset(&x, 0, sizeof x);
        x.t[0] = 1; x.t[1] = -2; x.t[2] = 3;
        x.r[0] = 30; x.r[1] = -50; x.r[2] = 70;
        x.s[0] = 1.5; x.s[1] = 0.5; x.s[2] = 2;
        x.order = o;
        expected_local(&x, m[o]);
        char label[64];
        snprintf(label, sizeof label, "RotationOrder %d (%s)", o, order_names[o]);
        check_single(&x, label);
    }
    for (int a = 0; a < 6; a++)
        for (int b = a + 1; b < 6; b++)
            CHECK_MSG(max_diff(m[a], m[b]) > 0.1, "orders %s and %s are indistinguishable here", order_names[a], order_names[b]);
    /* The formula itself, on one hand-checked product: XYZ (90, 0, 90) maps +x to +y. */
    double r[16];
    const double deg[3] = { 90, 0, 90 };
    euler(r, deg, "XYZ");
    CHECK_NEAR(r[0], 0, 1e-12);
    CHECK_NEAR(r[1], 1, 1e-12);
    CHECK_NEAR(r[2], 0, 1e-12);
    euler(r, deg, "ZYX");   /* Z first: +x -> +y, then X: +y -> +z */
    CHECK_NEAR(r[2], 1, 1e-12);
}

/* Each property alone on top of a rotated, translated base (order ZXY): the property must
 * change the matrix (so it was written and read) and the result must match the formula. */
static void test_each_property(void)
{
    xform base;
    memset(&base, 0, sizeof base);
    base.t[0] = 0.5; base.t[1] = 1; base.t[2] = -1.5;
    base.r[0] = 10; base.r[1] = 20; base.r[2] = 30;
    base.order = 4;
    double base_m[16], geo[16];
    expected_local(&base, base_m);
    for (int p = 0; p < 11; p++) {
        xform x = base;
        const char *name = "";
        switch (p) {
        case 0: name = "PreRotation"; x.pre[0] = 25; x.pre[1] = -35; x.pre[2] = 45; break;
        case 1: name = "PostRotation"; x.post[0] = -15; x.post[1] = 40; x.post[2] = 55; break;
        case 2: name = "RotationOffset"; x.roff[0] = 0.25; x.roff[1] = -0.75; x.roff[2] = 1.25; break;
        case 3: name = "RotationPivot"; x.rp[0] = 1; x.rp[1] = 2; x.rp[2] = -0.5; break;
        case 4: name = "ScalingOffset"; x.soff[0] = -0.3; x.soff[1] = 0.6; x.soff[2] = 0.9; break;
        case 5: name = "ScalingPivot+Scaling"; x.sp[0] = 0.4; x.sp[1] = -1.2; x.sp[2] = 2; x.s[0] = 2; x.s[1] = 0.5; x.s[2] = 3; break;
        case 6: name = "Lcl Scaling"; x.s[0] = 2; x.s[1] = 0.5; x.s[2] = 3; break;
        case 7: name = "GeometricTranslation"; x.gt[0] = 0.1; x.gt[1] = 0.2; x.gt[2] = 0.3; break;
        case 8: name = "GeometricRotation"; x.gr[0] = 60; x.gr[1] = -20; x.gr[2] = 10; break;
        case 9: name = "GeometricScaling"; x.gs[0] = 0.5; x.gs[1] = 4; x.gs[2] = 1.5; break;
        case 10: name = "RotationPivot+ScalingPivot+PostRotation (XYZ order)"; x.order = 0;
            x.rp[0] = 1; x.sp[1] = 1; x.s[1] = 2; x.post[2] = 90; break;
        }
        double local[16], m[16];
        expected_local(&x, local);
        expected_geometric(&x, geo);
        mul(m, local, geo);
        CHECK_MSG(max_diff(m, base_m) > 0.05, "%s: has no effect in the expected matrix", name);
        check_single(&x, name);
    }
}

/* Every property at once, in every rotation order. */
static const xform full = {
    .t = { 1, 2, 3 }, .r = { 30, -50, 70 }, .s = { 1.5, 0.75, 2.5 },
    .pre = { -20, 35, 15 }, .post = { 40, -25, 65 }, .roff = { 0.5, -0.25, 0.75 }, .rp = { -1, 0.5, 2 },
    .soff = { 0.2, 0.4, -0.6 }, .sp = { 1.5, -0.5, 0.25 },
    .gt = { 0.3, -0.2, 0.1 }, .gr = { 15, 25, -35 }, .gs = { 2, 0.5, 1.25 },
};

static void test_full_stack(void)
{
    for (int o = 0; o < 6; o++) {
        xform x = full;
        x.order = o;
        char label[64];
        snprintf(label, sizeof label, "full stack, RotationOrder %s", order_names[o]);
        check_single(&x, label);
    }
}

/* Grandparent -> parent -> child, each with its own full stack (and geometric transform, which
 * the children must not inherit): child world = GP.Local * P.Local * C.Local * C.Geometric. */
static void test_parent_chain(void)
{
    xform gp = full, p = full, c = full;
    gp.order = 2;
    p.order = 5;
    c.order = 1;
    for (int k = 0; k < 3; k++) {
        gp.t[k] *= -0.5; gp.r[k] = gp.r[k] * 0.5 + 5; gp.post[k] += 10;
        p.r[k] = -p.r[k]; p.rp[k] += 0.5; p.s[k] = 1.0 + 0.25 * k;
        c.t[k] += 1; c.pre[k] = -c.pre[k]; c.sp[k] -= 0.25;
    }
    double lgp[16], lp[16], lc[16], ggp[16], gpar[16], gc[16];
    expected_local(&gp, lgp);
    expected_local(&p, lp);
    expected_local(&c, lc);
    expected_geometric(&gp, ggp);
    expected_geometric(&p, gpar);
    expected_geometric(&c, gc);
    double wgp[16], wp[16], wc[16], e_gp[16], e_p[16], e_c[16];
    memcpy(wgp, lgp, sizeof wgp);
    mul(wp, wgp, lp);
    mul(wc, wp, lc);
    mul(e_gp, wgp, ggp);
    mul(e_p, wp, gpar);
    mul(e_c, wc, gc);
    for (int binary = 0; binary < 2; binary++) {
        fbxw_mesh m[3];
        /* Written child first, so the importer cannot rely on file order. */
        to_mesh(&c, "Child", 1, &m[0]);
        to_mesh(&p, "Parent", 2, &m[1]);
        to_mesh(&gp, "Grandparent", -1, &m[2]);
        mk_raw_asset raw;
        const char *label = binary ? "parent chain (binary)" : "parent chain (ASCII)";
        if (import_meshes(m, 3, binary, &raw) == 0) {
            check_world(&raw, "Grandparent", e_gp, label);
            check_world(&raw, "Parent", e_p, label);
            check_world(&raw, "Child", e_c, label);
        }
        mk_raw_free(&raw);
    }
}

/* InheritType 2 (Rrs, Maya's segment scale compensate): the parent's Lcl Scaling moves the
 * child but does not scale it: child world = ParentWorld * T * S_parent^-1 * (the rest of the
 * child's Local, from Roff on) * Geometric. The parent has no scaling pivot (the importer's
 * documented assumption). InheritType 0 (RrSs) is imported as RSrs (documented). */
static void test_inherit_types(void)
{
    xform p, c = full;
    memset(&p, 0, sizeof p);
    p.t[0] = -1; p.t[1] = 0.5; p.t[2] = 2;
    p.r[0] = 20; p.r[1] = 30; p.r[2] = -40;
    p.s[0] = 2; p.s[1] = 3; p.s[2] = 0.5;
    p.order = 3;
    c.order = 4;
    double lp[16], lc[16], gc[16], e[16], f[16];
    expected_local(&p, lp);
    expected_local(&c, lc);
    expected_geometric(&c, gc);
    for (int type = 0; type < 3; type++) {
        if (type == 2) {
            /* T * S_parent^-1 * T^-1 * Local = T * S_parent^-1 * (Roff ... Sp^-1) */
            double rest[16];
            translate(f, -c.t[0], -c.t[1], -c.t[2]);
            mul(rest, f, lc);
            translate(e, c.t[0], c.t[1], c.t[2]);
            mul(e, lp, e);
            scale(f, 1 / p.s[0], 1 / p.s[1], 1 / p.s[2]);
            then(e, f);
            then(e, rest);
        } else {
            mul(e, lp, lc);
        }
        then(e, gc);
        for (int binary = 0; binary < 2; binary++) {
            fbxw_mesh m[2];
            to_mesh(&p, "Parent", -1, &m[0]);
            to_mesh(&c, "Child", 0, &m[1]);
            m[1].inherit_type = FBXW_INHERIT(type);
            mk_raw_asset raw;
            char label[64];
            snprintf(label, sizeof label, "InheritType %d (%s)", type, binary ? "binary" : "ASCII");
            if (import_meshes(m, 2, binary, &raw) == 0) check_world(&raw, "Child", e, label);
            mk_raw_free(&raw);
        }
    }
}

CHECK_MAIN(CASE(test_rotation_orders), CASE(test_each_property), CASE(test_full_stack), CASE(test_parent_chain),
           CASE(test_inherit_types))
