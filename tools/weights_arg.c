/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "weights_arg.h"

/* Meshes of one node share their channels' weights: glTF primitives of one node instance. */
static int64_t node_key(const mk_asset *a, uint32_t mesh)
{
    mk_mesh_info m;
    mk_mesh_get(a, mesh, &m);
    return m.gltf_node >= 0 ? m.gltf_node : -1 - (int64_t)mesh;
}

static const char *mesh_name(const mk_asset *a, uint32_t mesh)
{
    mk_mesh_info m;
    mk_mesh_get(a, mesh, &m);
    return m.name;
}

/* Every channel named `channel` on meshes named `node` (node NULL: any). Returns the count;
 * the first `cap` indices go to out. */
static uint32_t find(const mk_asset *a, const char *node, const char *channel, uint32_t *out, uint32_t cap)
{
    uint32_t n = 0;
    for (uint32_t c = 0; c < a->channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(a, c, &ch);
        if (strcmp(ch.name, channel) || (node && strcmp(mesh_name(a, ch.mesh), node))) continue;
        if (n < cap) out[n] = c;
        n++;
    }
    return n;
}

/* Appends "'name'" to a list in buf unless already there; keeps room for "...". */
static void list_add(char *buf, size_t size, const char *name)
{
    char item[300];
    snprintf(item, sizeof item, "'%.280s'", name);
    for (const char *p = strstr(buf, item); p; p = strstr(p + 1, item))
        if ((p == buf || p[-1] == ' ') && (p[strlen(item)] == ',' || p[strlen(item)] == 0)) return;
    size_t n = strlen(buf);
    if (n + strlen(item) + 8 >= size) {
        if (n + 5 < size && !strstr(buf, "...")) strcat(buf, ", ...");
        return;
    }
    snprintf(buf + n, size - n, "%s%s", n ? ", " : "", item);
}

/* Resolves one name to channel indices (all on one node). Returns the count, or 0 with why. */
static uint32_t resolve(const mk_asset *a, const char *name, uint32_t *out, uint32_t cap, char *why, size_t why_size)
{
    uint32_t n = find(a, NULL, name, out, cap);
    if (n > cap) n = cap;
    if (n) {
        for (uint32_t i = 1; i < n; i++) {
            mk_channel_info first, other;
            mk_channel_get(a, out[0], &first);
            mk_channel_get(a, out[i], &other);
            if (node_key(a, first.mesh) == node_key(a, other.mesh)) continue;
            char nodes[600] = "";
            for (uint32_t k = 0; k < n; k++) {
                mk_channel_info ch;
                mk_channel_get(a, out[k], &ch);
                list_add(nodes, sizeof nodes, mesh_name(a, ch.mesh));
            }
            snprintf(why, why_size, "channel '%s' is on several nodes: %s; write NODE/%s", name, nodes, name);
            return 0;
        }
        return n;
    }
    /* NODE/CHANNEL, split at any '/' (names may contain slashes). */
    for (const char *slash = strchr(name, '/'); slash; slash = strchr(slash + 1, '/')) {
        char node[512];
        size_t len = (size_t)(slash - name);
        if (len >= sizeof node) break;
        memcpy(node, name, len);
        node[len] = 0;
        n = find(a, node, slash + 1, out, cap);
        if (n > cap) n = cap;
        if (n) return n;
    }
    char *end;
    long index = strtol(name, &end, 10);
    if (!*end && end != name && index >= 0 && index < (long)a->channel_count) {
        out[0] = (uint32_t)index;
        return 1;
    }
    char names[700] = "";
    for (uint32_t c = 0; c < a->channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(a, c, &ch);
        list_add(names, sizeof names, ch.name);
    }
    snprintf(why, why_size, "no channel named '%.200s'; the channels are %s (or 0 to %u by index)", name,
             names[0] ? names : "(none)", a->channel_count ? a->channel_count - 1 : 0);
    return 0;
}

int weights_arg_apply(const mk_asset *a, const char *spec, float *weights, char *why, size_t why_size)
{
    size_t len = strlen(spec);
    char *copy = malloc(len + 1);
    uint32_t *found = malloc(((size_t)a->channel_count + 1) * sizeof *found);
    int status = -1;
    if (!copy || !found) {
        snprintf(why, why_size, "out of memory");
        goto done;
    }
    memcpy(copy, spec, len + 1);
    for (char *item = copy, *next; item; item = next) {
        next = strchr(item, ',');
        if (next) *next++ = 0;
        char *eq = strrchr(item, '=');
        if (!item[0]) {
            snprintf(why, why_size, "an item of \"%.200s\" is empty (write NAME=V,NAME=V)", spec);
            goto done;
        }
        if (!eq) {
            snprintf(why, why_size, "'%.200s' needs NAME=VALUE", item);
            goto done;
        }
        *eq = 0;
        if (!item[0]) {
            snprintf(why, why_size, "'=%.200s' has no channel name", eq + 1);
            goto done;
        }
        char *end;
        double v = strtod(eq + 1, &end);
        if (!eq[1] || *end || !isfinite(v) || fabs(v) > 1e30) {
            snprintf(why, why_size, "'%.200s=%.100s': the weight must be a finite number", item, eq + 1);
            goto done;
        }
        uint32_t n = resolve(a, item, found, a->channel_count + 1, why, why_size);
        if (!n) goto done;
        for (uint32_t i = 0; i < n; i++) weights[found[i]] = (float)v;
    }
    status = 0;
done:
    free(copy);
    free(found);
    return status;
}
