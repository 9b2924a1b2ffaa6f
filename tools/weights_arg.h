/* SPDX-License-Identifier: MIT */
/* --weights NAME=V,... : channel weights given by name on the command line. */
#ifndef MK_WEIGHTS_ARG_H
#define MK_WEIGHTS_ARG_H

#include <stddef.h>
#include "morphkit.h"

/* Sets asset-wide weights from "NAME=V,NODE/NAME=V,INDEX=V". A name sets every channel of
 * that name on one node: a glTF mesh's primitives all carry the mesh's channels and share
 * its weights. A name found on several different nodes is an error listing them, resolved by
 * writing NODE/NAME; an unknown name is an error listing the available names; a number that
 * is no channel's name is a channel index. Returns 0, or -1 with the reason in why. */
int weights_arg_apply(const mk_asset *asset, const char *spec, float *weights, char *why, size_t why_size);

#endif
