/* SPDX-License-Identifier: MIT */
/* Lattice control-point moves of the FFD ops (lattice_moves.c). */
#ifndef MORPHKIT_RECIPE_LATTICE_MOVES_H
#define MORPHKIT_RECIPE_LATTICE_MOVES_H

#include "recipe_op.h"
#include "ffd_prism.h"

/* The moves in obj's field (at path; "moves", or ffd_prism's "rest_moves") applied to a lattice
 * of dims control points (point (i, j, k) at index i + dims[0] (j + dims[1] k)), or with prism
 * set to its rings (i = ring 0..dims[0]-1, j = position around ring i, k = layer
 * 0..dims[2]-1; without "j" a move takes whole rings): current starts as a copy of rest and
 * ends moved; displacements gets moved - rest. */
mk_result recipe_lattice_moves(recipe_ctx *ctx, const uint32_t dims[3], const mk_prism_lattice *prism,
                               const cJSON *obj, const char *path, const char *field, const double *rest,
                               double *current, double *displacements);

#endif
