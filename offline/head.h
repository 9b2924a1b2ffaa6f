/* SPDX-License-Identifier: MIT */
/* A head made by code, for the deformation transfer sample and its tests (head.c): a smooth
 * closed surface with a nose, a brow and a chin facing +z (height 2 along y, width 1.6, depth
 * 1.8), a handful of facial expressions as displacement fields on it, and a smooth non-rigid warp
 * that gives another character's proportions. Because the surface, the expressions and the warp
 * are functions, a test knows the true result of transferring an expression onto a warped head
 * of any tessellation: W(x + d_k(x)) at the target vertex W(x). */
#ifndef MK_HEAD_H
#define MK_HEAD_H

#include "raw.h"

/* The head's surface point in the direction dir from the head's centre (any length but 0). */
void mk_head_surface(const double dir[3], double out[3]);

/* The warp W with amplitude a (0: identity, 1: the full warp): about 15 % wider at the brow, the
 * midline curved sideways, the mid-face 12 % deeper. Smooth and one to one for a in [0, 1]. */
void mk_head_warp(double a, const double p[3], double out[3]);

/* The expressions: jaw_open (a rotation of the lower face, nonlinear in the weight), smile_left,
 * smile_right, brow_raise, cheek_puff, nose_wrinkle. mk_head_expression moves the surface point p
 * to the expression at weight w (1: full). */
#define MK_HEAD_EXPRESSIONS 6
const char *mk_head_expression_name(uint32_t k);
void mk_head_expression(uint32_t k, double w, const double p[3], double out[3]);

/* Adds the head as a mesh named `name`: an icosphere of `levels` (10 * 4^levels + 2 vertices)
 * when uv is 0, else a UV sphere of `levels` rings and 2 * `levels` segments (poles on y), with
 * its directions turned by `turn` radians about y first (another tessellation of the same
 * surface), pushed onto the head and warped with amplitude `warp`; outward normals. dirs (may be
 * NULL) receives the unit direction of every vertex (3 doubles each, malloc'ed; the caller
 * frees). With `expressions`, adds one channel per expression (one target at weight 1, and
 * jaw_open an in-between at 0.5), moved on the unwarped head then warped. NULL when memory runs
 * out. */
mk_raw_mesh *mk_raw_add_head(mk_raw_asset *raw, const char *name, uint32_t levels, int uv, double turn, double warp,
                             int expressions, double **dirs);

/* Up to 12 marker pairs between a head `src` and another head `dst` (their vertices' directions
 * sdir, ddir as mk_raw_add_head gives them): at the nose tip, chin, brow centre, eyes, mouth
 * corners, cheeks, crown and both sides, the src vertex nearest the feature's direction and the
 * dst vertex nearest to it, which is moved (with its direction) onto the same surface point of
 * dst's head, warped by `warp`: a pair is one feature on both, as an artist would pick it. */
void mk_head_marker_pairs(const mk_raw_mesh *src, const double *sdir, mk_raw_mesh *dst, double *ddir, double warp,
                          uint32_t count, uint32_t (*pairs)[2]);

#endif
