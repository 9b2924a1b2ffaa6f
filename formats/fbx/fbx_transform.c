/* SPDX-License-Identifier: MIT */
/* FBX node transforms at rest.
 *
 * The FBX SDK transform stack (FBX SDK "Computing transformation matrix", FbxNode docs; ufbx
 * ufbxi_get_transform):
 *   Local = T * Roff * Rp * Rpre * R * Rpost^-1 * Rp^-1 * Soff * Sp * S * Sp^-1
 *   World = ParentWorld * Local;  geometry to world = World * Tg * Rg * Sg
 * T/R/S are Lcl Translation/Rotation/Scaling; Roff/Rp RotationOffset/RotationPivot, Soff/Sp
 * ScalingOffset/ScalingPivot, Rpre/Rpost PreRotation/PostRotation (always XYZ order), R uses
 * RotationOrder (0 XYZ .. 5 ZYX; "XYZ" means X is applied first: R = Rz Ry Rx for column
 * vectors). The geometric transform applies to the mesh only, not to child nodes. Angles are
 * degrees. Matrices are column-major doubles, m[col * 4 + row].
 *
 * FBX 5 files (3ds Max 7) have no property block: the rest values are the `Default`s of the
 * Channel: "Transform" { Channel: "T"/"R"/"S" { Channel: "X"/"Y"/"Z" } } tree.
 */
#include <math.h>
#include <string.h>
#include "mat4.h"
#include "fbx_transform.h"

static void translation(double m[16], const double t[3], double sign)
{
    mk_mat4d_identity(m);
    m[12] = sign * t[0];
    m[13] = sign * t[1];
    m[14] = sign * t[2];
}

static void scaling(double m[16], const double s[3])
{
    mk_mat4d_identity(m);
    m[0] = s[0];
    m[5] = s[1];
    m[10] = s[2];
}

static void axis_rotation(double m[16], int axis, double degrees)
{
    double a = degrees * (3.14159265358979323846 / 180.0);
    double c = cos(a), s = sin(a);
    mk_mat4d_identity(m);
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    m[i * 4 + i] = c;
    m[j * 4 + i] = -s;
    m[i * 4 + j] = s;
    m[j * 4 + j] = c;
}

/* order: 0 XYZ, 1 XZY, 2 YZX, 3 YXZ, 4 ZXY, 5 ZYX (first letter applied first). */
static void euler(double m[16], const double degrees[3], int order)
{
    static const int sequence[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 2, 0 }, { 1, 0, 2 }, { 2, 0, 1 }, { 2, 1, 0 } };
    if (order < 0 || order > 5) order = 0;  /* 6 = spheric XYZ: treated as XYZ */
    mk_mat4d_identity(m);
    for (int k = 0; k < 3; k++) {
        int axis = sequence[order][k];
        double r[16];
        axis_rotation(r, axis, degrees[axis]);
        mk_mat4d_multiply(m, r, m);  /* later rotations multiply on the left */
    }
}

static void transpose3(double m[16])
{
    /* Inverse of a pure rotation. */
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++) {
            double t = m[j * 4 + i];
            m[j * 4 + i] = m[i * 4 + j];
            m[i * 4 + j] = t;
        }
}

static void legacy_channel_vec3(const fbx_node *transform, const char *name, double out[3])
{
    const fbx_node *ch = NULL;
    while ((ch = fbx_next_child(transform, ch, "Channel")) != NULL) {
        const char *s;
        uint32_t n;
        if (ch->value_count < 1 || !fbx_value_string(&ch->values[0], &s, &n)) continue;
        if (n != strlen(name) || memcmp(s, name, n) != 0) continue;
        static const char *axes[3] = { "X", "Y", "Z" };
        const fbx_node *sub = NULL;
        while ((sub = fbx_next_child(ch, sub, "Channel")) != NULL) {
            if (sub->value_count < 1 || !fbx_value_string(&sub->values[0], &s, &n) || n != 1) continue;
            for (int a = 0; a < 3; a++) {
                double v;
                if (s[0] == axes[a][0] && fbx_child_float(sub, "Default", &v)) out[a] = v;
            }
        }
    }
}

void fbx_model_transforms(const fbx_node *model, double local[16], double geometric[16])
{
    double t[3] = { 0, 0, 0 }, r[3] = { 0, 0, 0 }, s[3] = { 1, 1, 1 };
    double roff[3] = { 0, 0, 0 }, rp[3] = { 0, 0, 0 }, soff[3] = { 0, 0, 0 }, sp[3] = { 0, 0, 0 };
    double pre[3] = { 0, 0, 0 }, post[3] = { 0, 0, 0 };
    double gt[3] = { 0, 0, 0 }, gr[3] = { 0, 0, 0 }, gs[3] = { 1, 1, 1 };
    int64_t order = 0;
    fbx_props props = fbx_props_of(model);
    if (props.block) {
        fbx_prop_vec3(props, "Lcl Translation", t);
        fbx_prop_vec3(props, "Lcl Rotation", r);
        fbx_prop_vec3(props, "Lcl Scaling", s);
        fbx_prop_vec3(props, "RotationOffset", roff);
        fbx_prop_vec3(props, "RotationPivot", rp);
        fbx_prop_vec3(props, "ScalingOffset", soff);
        fbx_prop_vec3(props, "ScalingPivot", sp);
        fbx_prop_vec3(props, "PreRotation", pre);
        fbx_prop_vec3(props, "PostRotation", post);
        fbx_prop_vec3(props, "GeometricTranslation", gt);
        fbx_prop_vec3(props, "GeometricRotation", gr);
        fbx_prop_vec3(props, "GeometricScaling", gs);
        fbx_prop_int64(props, "RotationOrder", &order);
    } else {
        const fbx_node *ch = NULL;
        while ((ch = fbx_next_child(model, ch, "Channel")) != NULL) {
            const char *name;
            uint32_t n;
            if (ch->value_count >= 1 && fbx_value_string(&ch->values[0], &name, &n) && n == 9 &&
                memcmp(name, "Transform", 9) == 0) {
                legacy_channel_vec3(ch, "T", t);
                legacy_channel_vec3(ch, "R", r);
                legacy_channel_vec3(ch, "S", s);
            }
        }
    }
    double m[16], x[16];
    translation(local, t, 1);
    translation(x, roff, 1); mk_mat4d_multiply(local, local, x);
    translation(x, rp, 1); mk_mat4d_multiply(local, local, x);
    euler(x, pre, 0); mk_mat4d_multiply(local, local, x);
    euler(x, r, (int)order); mk_mat4d_multiply(local, local, x);
    euler(x, post, 0); transpose3(x); mk_mat4d_multiply(local, local, x);
    translation(x, rp, -1); mk_mat4d_multiply(local, local, x);
    translation(x, soff, 1); mk_mat4d_multiply(local, local, x);
    translation(x, sp, 1); mk_mat4d_multiply(local, local, x);
    scaling(x, s); mk_mat4d_multiply(local, local, x);
    translation(x, sp, -1); mk_mat4d_multiply(local, local, x);

    translation(geometric, gt, 1);
    euler(m, gr, 0); mk_mat4d_multiply(geometric, geometric, m);
    scaling(m, gs); mk_mat4d_multiply(geometric, geometric, m);
}

int fbx_model_inherit_type(const fbx_node *model)
{
    int64_t type = 1;
    fbx_prop_int64(fbx_props_of(model), "InheritType", &type);
    return type >= 0 && type <= 2 ? (int)type : 1;
}

void fbx_model_scaling(const fbx_node *model, double out[3])
{
    out[0] = out[1] = out[2] = 1.0;
    fbx_prop_vec3(fbx_props_of(model), "Lcl Scaling", out);
}
