// SPDX-License-Identifier: MIT
// raw model → glTF 2.0 (.gltf with an embedded buffer, or .glb), written with tinygltf's
// serializer, plus the channel sidecar that lets a re-import restore progressive channels
// (format and behaviour: docs/importing-gltf.md).
//
// Layout. Raw meshes that came from one glTF node (gltf_node) become the primitives of one
// node again, keeping the node index and primitive order, so references that name
// (node, mesh, primitive) still match; other meshes get new nodes after them. Mesh indices are
// renumbered densely. Each node's matrix is the raw world transform (no hierarchy).
//
// Targets. glTF has one target slot list per mesh, one weight per slot, and no in-betweens.
// A channel with n targets (full weights f_1 < ... < f_n) becomes n slots whose weights are
// the coefficients of the runtime's piecewise-linear playback: at channel weight w,
// D(w) = ca·Δ_ia + cb·Δ_ib (mk_channel_span), so slot ia gets ca, slot ib gets cb, the others
// 0. Because the slot weights sum back as w = Σ f_k u_k, the importer recovers w exactly.
// Primitives of a node share slots when their channel structure and animation agree (the usual
// glTF case); otherwise each primitive gets its own slots and the others get empty padding
// targets, listed as unused in the sidecar.
//
// Animation. A clip becomes an animation (same order). A node's weights are exported exactly
// (STEP / LINEAR / CUBICSPLINE, slopes per second as glTF's tangents) when every slot is a
// plain f = 1 channel and all animated channels share key times and one interpolation kind;
// otherwise they are resampled to LINEAR keys at every key time, at the times where a channel
// weight crosses a full weight (where the slot weights bend), just before/after constant
// jumps, and every 1/60 s inside cubic segments.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_USE_CPP14
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "gltf_export.h"
#include "gltf_weights.h"
extern "C" {
#include "blob_io.h"
}

namespace {

struct Slot {
    uint32_t driver;        // index into Group::drivers
    uint32_t target;        // target index within the driver channel
    int owner;              // primitive owning the data (-1: every primitive, shared slots)
};

struct Group {
    int node = -1;
    std::vector<uint32_t> prims;          // raw mesh indices, in primitive order
    std::vector<std::vector<uint32_t>> channels;   // per prim: raw channel indices in order
    bool shared = true;
    std::vector<uint32_t> drivers;        // raw channels whose weights drive the slots
    std::vector<Slot> slots;
};

struct Exporter {
    const mk_raw_asset *raw;
    tinygltf::Model model;
    mk_gltf_export_report rep{};
    std::vector<Group> groups;
    bool exported_clips = false;   // every clip became an animation (indices aligned)

    std::vector<unsigned char> &buf() { return model.buffers[0].data; }

    int add_view(const void *data, size_t bytes, int target)
    {
        std::vector<unsigned char> &b = buf();
        while (b.size() % 4) b.push_back(0);
        tinygltf::BufferView v;
        v.buffer = 0;
        v.byteOffset = b.size();
        v.byteLength = bytes;
        v.target = target;
        const unsigned char *p = static_cast<const unsigned char *>(data);
        b.insert(b.end(), p, p + bytes);
        model.bufferViews.push_back(v);
        return (int)model.bufferViews.size() - 1;
    }

    // Float accessor with exact min/max (the validator compares them with the data).
    int add_floats(const float *v, size_t count, int comps, int type, int target, bool minmax)
    {
        tinygltf::Accessor a;
        a.bufferView = add_view(v, count * comps * sizeof(float), target);
        a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        a.count = count;
        a.type = type;
        if (minmax) set_minmax(a, v, count, comps, count);
        model.accessors.push_back(a);
        return (int)model.accessors.size() - 1;
    }

    static void set_minmax(tinygltf::Accessor &a, const float *v, size_t n, int comps, size_t total)
    {
        a.minValues.assign(comps, 0.0);
        a.maxValues.assign(comps, 0.0);
        for (int c = 0; c < comps; ++c) {
            float lo = n ? v[c] : 0.0f, hi = lo;
            for (size_t i = 0; i < n; ++i) { lo = std::min(lo, v[i * comps + c]); hi = std::max(hi, v[i * comps + c]); }
            if (n < total) { lo = std::min(lo, 0.0f); hi = std::max(hi, 0.0f); }   // implicit zeros
            a.minValues[c] = lo;
            a.maxValues[c] = hi;
        }
    }

    // Target deltas: zeros without bufferView when nothing moves, sparse when few vertices
    // move, dense otherwise (spec §3.6.2.3).
    int add_deltas(const mk_raw_target *t, const float *values, uint32_t vertex_count)
    {
        tinygltf::Accessor a;
        a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        a.count = vertex_count;
        a.type = TINYGLTF_TYPE_VEC3;
        a.bufferView = -1;
        uint32_t n = t ? t->count : 0;
        if (n == 0) {
            a.minValues.assign(3, 0.0);
            a.maxValues.assign(3, 0.0);
        } else if ((uint64_t)n * 2 < vertex_count) {
            set_minmax(a, values, n, 3, vertex_count);
            a.sparse.isSparse = true;
            a.sparse.count = (int)n;
            a.sparse.indices.bufferView = add_view(t->indices, n * sizeof(uint32_t), 0);
            a.sparse.indices.byteOffset = 0;
            a.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            a.sparse.values.bufferView = add_view(values, n * 3 * sizeof(float), 0);
            a.sparse.values.byteOffset = 0;
        } else {
            std::vector<float> dense((size_t)vertex_count * 3, 0.0f);
            for (uint32_t i = 0; i < n; ++i)
                for (int c = 0; c < 3; ++c) dense[(size_t)t->indices[i] * 3 + c] = values[(size_t)i * 3 + c];
            a.bufferView = add_view(dense.data(), dense.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
            set_minmax(a, dense.data(), vertex_count, 3, vertex_count);
        }
        model.accessors.push_back(a);
        return (int)model.accessors.size() - 1;
    }

    // Slot weights of channel c at channel weight w (gltf_weights.h).
    void slot_weights(uint32_t c, float w, std::vector<float> &u)
    {
        u.assign(raw->channels[c].target_count, 0.0f);
        mk_gltf_slot_weights(&raw->channels[c], w, u.data());
    }

    const mk_raw_track *track_of(const mk_raw_clip &clip, uint32_t c)
    {
        for (uint32_t t = 0; t < clip.track_count; ++t)
            if (clip.tracks[t].channel == c && clip.tracks[t].key_count) return &clip.tracks[t];
        return nullptr;
    }

    bool same_channel(uint32_t a, uint32_t b)
    {
        const mk_raw_channel &x = raw->channels[a], &y = raw->channels[b];
        if (x.target_count != y.target_count || x.default_weight != y.default_weight) return false;
        for (uint32_t k = 0; k < x.target_count; ++k)
            if (x.targets[k].full_weight != y.targets[k].full_weight) return false;
        for (uint32_t c = 0; c < raw->clip_count; ++c) {
            const mk_raw_track *ta = track_of(raw->clips[c], a), *tb = track_of(raw->clips[c], b);
            if (!ta != !tb) return false;
            if (ta && (ta->key_count != tb->key_count || std::memcmp(ta->keys, tb->keys, ta->key_count * sizeof(mk_key)) != 0))
                return false;
        }
        return true;
    }

    void plan_groups()
    {
        std::map<int, size_t> by_node;
        int next_node = 0;
        for (uint32_t m = 0; m < raw->mesh_count; ++m)
            next_node = std::max(next_node, raw->meshes[m].gltf_node + 1);
        for (uint32_t m = 0; m < raw->mesh_count; ++m) {
            const mk_raw_mesh &mesh = raw->meshes[m];
            bool joined = false;
            if (mesh.gltf_node >= 0) {
                auto it = by_node.find(mesh.gltf_node);
                if (it != by_node.end()) {
                    Group &g = groups[it->second];
                    const mk_raw_mesh &first = raw->meshes[g.prims[0]];
                    if (std::memcmp(first.world, mesh.world, sizeof mesh.world) == 0) {
                        g.prims.push_back(m);
                        joined = true;
                    }
                }
            }
            if (joined) continue;
            Group g;
            g.node = mesh.gltf_node >= 0 && !by_node.count(mesh.gltf_node) ? mesh.gltf_node : next_node++;
            g.prims.push_back(m);
            if (mesh.gltf_node >= 0 && !by_node.count(mesh.gltf_node)) by_node[mesh.gltf_node] = groups.size();
            groups.push_back(g);
        }
        for (Group &g : groups) {
            std::stable_sort(g.prims.begin(), g.prims.end(), [&](uint32_t a, uint32_t b) {
                return raw->meshes[a].gltf_primitive < raw->meshes[b].gltf_primitive;
            });
            for (uint32_t m : g.prims) {
                std::vector<uint32_t> chs;
                for (uint32_t c = 0; c < raw->channel_count; ++c)
                    if (raw->channels[c].mesh == m) chs.push_back(c);
                g.channels.push_back(chs);
            }
            for (size_t p = 1; p < g.prims.size() && g.shared; ++p) {
                if (g.channels[p].size() != g.channels[0].size()) { g.shared = false; break; }
                for (size_t i = 0; i < g.channels[0].size(); ++i)
                    if (!same_channel(g.channels[0][i], g.channels[p][i])) { g.shared = false; break; }
            }
            for (size_t p = 0; p < (g.shared ? 1 : g.prims.size()); ++p)
                for (uint32_t c : g.channels[p]) {
                    uint32_t d = (uint32_t)g.drivers.size();
                    g.drivers.push_back(c);
                    if (raw->channels[c].target_count > 1) rep.progressive_channels++;
                    for (uint32_t k = 0; k < raw->channels[c].target_count; ++k)
                        g.slots.push_back(Slot{d, k, g.shared ? -1 : (int)p});
                }
        }
    }

    void export_primitive(const Group &g, size_t p, tinygltf::Mesh &gm)
    {
        const mk_raw_mesh &m = raw->meshes[g.prims[p]];
        uint32_t vc = m.vertex_count;
        tinygltf::Primitive prim;
        prim.attributes["POSITION"] = add_floats(m.positions, vc, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
        if (m.normals) {
            // The validator requires unit normals; the runtime normalizes anyway.
            // A zero normal (some FBX exporters write them) gets the area-weighted normal of
            // its triangles, else +Z, and is counted in the report.
            std::vector<float> n(m.normals, m.normals + (size_t)vc * 3);
            std::vector<double> face((size_t)vc * 3, 0.0);
            for (uint32_t t = 0; t < m.triangle_count; ++t) {
                const uint32_t *tri = &m.triangles[(size_t)t * 3];
                const float *a = &m.positions[(size_t)tri[0] * 3], *b = &m.positions[(size_t)tri[1] * 3], *c = &m.positions[(size_t)tri[2] * 3];
                double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
                double fn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
                for (int k = 0; k < 3; ++k)
                    for (int q = 0; q < 3; ++q) face[(size_t)tri[k] * 3 + q] += fn[q];
            }
            for (uint32_t v = 0; v < vc; ++v) {
                float *x = &n[(size_t)v * 3];
                float len = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
                if (!(len > 1e-12f)) {
                    double *f = &face[(size_t)v * 3];
                    double fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
                    if (fl > 0) for (int c = 0; c < 3; ++c) x[c] = (float)(f[c] / fl);
                    else { x[0] = 0; x[1] = 0; x[2] = 1; }
                    rep.fixed_normals++;
                    continue;
                }
                for (int c = 0; c < 3; ++c) x[c] /= len;
            }
            prim.attributes["NORMAL"] = add_floats(n.data(), vc, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, false);
        }
        if (m.tangents && m.normals) {
            std::vector<float> t(m.tangents, m.tangents + (size_t)vc * 4);
            for (uint32_t v = 0; v < vc; ++v) {
                float *x = &t[(size_t)v * 4];
                float len = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
                if (len > 1e-12f) for (int c = 0; c < 3; ++c) x[c] /= len;
                else { x[0] = 1; x[1] = 0; x[2] = 0; rep.fixed_normals++; }
                x[3] = x[3] < 0 ? -1.0f : 1.0f;
            }
            prim.attributes["TANGENT"] = add_floats(t.data(), vc, 4, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER, false);
        }
        if (m.triangle_count) {
            tinygltf::Accessor a;
            size_t n = (size_t)m.triangle_count * 3;
            if (vc <= 65535) {
                std::vector<uint16_t> idx(n);
                for (size_t i = 0; i < n; ++i) idx[i] = (uint16_t)m.triangles[i];
                a.bufferView = add_view(idx.data(), n * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
                a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
            } else {
                a.bufferView = add_view(m.triangles, n * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
                a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            }
            a.count = n;
            a.type = TINYGLTF_TYPE_SCALAR;
            model.accessors.push_back(a);
            prim.indices = (int)model.accessors.size() - 1;
            prim.mode = TINYGLTF_MODE_TRIANGLES;
        } else {
            prim.mode = TINYGLTF_MODE_POINTS;
        }
        for (const Slot &s : g.slots) {
            const mk_raw_target *t = nullptr;
            if (s.owner < 0 || (size_t)s.owner == p) {
                // Shared slots: this primitive's own channel at the same position.
                uint32_t c = g.drivers[s.driver];
                if (g.shared && p > 0) {
                    size_t i = (size_t)(std::find(g.channels[0].begin(), g.channels[0].end(), c) - g.channels[0].begin());
                    c = g.channels[p][i];
                }
                t = &raw->channels[c].targets[s.target];
            } else {
                rep.padding_targets++;
            }
            std::map<std::string, int> attrs;
            attrs["POSITION"] = add_deltas(t, t ? t->positions : nullptr, vc);
            if (t && t->normals && m.normals) attrs["NORMAL"] = add_deltas(t, t->normals, vc);
            if (t && t->tangents && m.tangents && m.normals) attrs["TANGENT"] = add_deltas(t, t->tangents, vc);
            prim.targets.push_back(attrs);
            rep.targets++;
        }
        gm.primitives.push_back(prim);
    }

    std::string slot_name(const Group &g, const Slot &s)
    {
        const mk_raw_channel &ch = raw->channels[g.drivers[s.driver]];
        std::string cn = ch.name ? ch.name : "";
        if (ch.target_count == 1) return cn;
        const mk_raw_target &t = ch.targets[s.target];
        std::ostringstream o;
        o << cn << "@" << t.full_weight;
        return o.str();
    }

    void export_clip(uint32_t ci, const Group &g, int node, tinygltf::Animation &anim)
    {
        const mk_raw_clip &clip = raw->clips[ci];
        std::vector<const mk_raw_track *> tr(g.drivers.size());
        bool any = false;
        for (size_t d = 0; d < g.drivers.size(); ++d) any |= (tr[d] = track_of(clip, g.drivers[d])) != nullptr;
        if (!any) return;
        size_t T = g.slots.size();

        // Exact export?
        bool exact = true;
        const mk_raw_track *ref = nullptr;
        int kind = -1;   // mk_interp of every segment
        for (size_t d = 0; d < g.drivers.size() && exact; ++d) {
            const mk_raw_channel &ch = raw->channels[g.drivers[d]];
            if (ch.target_count != 1 || ch.targets[0].full_weight != 1.0f) exact = false;
            const mk_raw_track *t = tr[d];
            if (!t) continue;
            if (!ref) ref = t;
            if (t->key_count != ref->key_count) { exact = false; break; }
            for (uint32_t k = 0; k < t->key_count; ++k) {
                if (t->keys[k].time != ref->keys[k].time) exact = false;
                if (k + 1 == t->key_count) break;
                int in = (int)t->keys[k].interp;
                if (in == MK_INTERP_CUBIC && (std::fabs(t->keys[k].right_weight - 1.0f / 3) > 1e-6f ||
                                              std::fabs(t->keys[k + 1].left_weight - 1.0f / 3) > 1e-6f)) exact = false;
                if (in == MK_INTERP_CONSTANT_NEXT) exact = false;
                if (kind < 0) kind = in;
                else if (kind != in) exact = false;
            }
        }
        if (kind < 0) kind = MK_INTERP_LINEAR;

        std::vector<float> times, values;
        std::string interp = "LINEAR";
        std::vector<float> u;
        if (exact) {
            bool cubic = kind == MK_INTERP_CUBIC;
            interp = kind == MK_INTERP_CONSTANT ? "STEP" : cubic ? "CUBICSPLINE" : "LINEAR";
            for (uint32_t k = 0; k < ref->key_count; ++k) times.push_back(ref->keys[k].time);
            size_t K = times.size();
            values.assign(K * T * (cubic ? 3 : 1), 0.0f);
            for (size_t k = 0; k < K; ++k)
                for (size_t s = 0; s < T; ++s) {
                    const mk_raw_track *t = tr[g.slots[s].driver];
                    float v = t ? t->keys[k].value : raw->channels[g.drivers[g.slots[s].driver]].default_weight;
                    if (cubic) {
                        // glTF tangents are d(weight)/d(second), as mk_key slopes are; the
                        // first in-tangent and last out-tangent are 0 by convention.
                        values[k * 3 * T + s] = t && k > 0 ? t->keys[k].left_slope : 0.0f;
                        values[k * 3 * T + T + s] = v;
                        values[k * 3 * T + 2 * T + s] = t && k + 1 < K ? t->keys[k].right_slope : 0.0f;
                    } else {
                        values[k * T + s] = v;
                    }
                }
        } else {
            rep.resampled_tracks++;
            for (size_t d = 0; d < g.drivers.size(); ++d) {
                const mk_raw_track *t = tr[d];
                if (!t) continue;
                const mk_raw_channel &ch = raw->channels[g.drivers[d]];
                std::vector<float> inside(MK_GLTF_SEGMENT_TIMES);
                for (uint32_t k = 0; k < t->key_count; ++k) {
                    times.push_back(t->keys[k].time);
                    if (k + 1 == t->key_count) break;
                    uint32_t n = mk_gltf_segment_times(&t->keys[k], &t->keys[k + 1], &ch, inside.data());
                    times.insert(times.end(), inside.begin(), inside.begin() + n);
                }
            }
            times.resize(mk_gltf_unique_times(times.data(), times.size()));
            values.assign(times.size() * T, 0.0f);
            for (size_t k = 0; k < times.size(); ++k) {
                for (size_t d = 0; d < g.drivers.size(); ++d) {
                    float w = tr[d] ? mk_curve_eval(tr[d]->keys, tr[d]->key_count, times[k], nullptr)
                                    : raw->channels[g.drivers[d]].default_weight;
                    slot_weights(g.drivers[d], w, u);
                    for (size_t s = 0; s < T; ++s)
                        if (g.slots[s].driver == d) values[k * T + s] = u[g.slots[s].target];
                }
            }
        }
        tinygltf::AnimationSampler smp;
        smp.input = add_floats(times.data(), times.size(), 1, TINYGLTF_TYPE_SCALAR, 0, true);
        smp.output = add_floats(values.data(), values.size(), 1, TINYGLTF_TYPE_SCALAR, 0, false);
        smp.interpolation = interp;
        anim.samplers.push_back(smp);
        tinygltf::AnimationChannel ch;
        ch.sampler = (int)anim.samplers.size() - 1;
        ch.target_node = node;
        ch.target_path = "weights";
        anim.channels.push_back(ch);
    }

    nlohmann::json sidecar_json()
    {
        nlohmann::json meshes = nlohmann::json::array();
        for (const Group &g : groups) {
            for (size_t p = 0; p < g.prims.size(); ++p) {
                const mk_raw_mesh &m = raw->meshes[g.prims[p]];
                nlohmann::json e;
                e["node"] = g.node;
                e["primitive"] = p;
                e["name"] = m.name ? m.name : "";
                e["stacking"] = m.stacking == MK_STACKING_SEQUENTIAL ? "sequential" : "additive";
                nlohmann::json chans = nlohmann::json::array();
                std::vector<bool> used(g.slots.size(), false);
                for (uint32_t c : g.channels[p]) {
                    const mk_raw_channel &ch = raw->channels[c];
                    // The driver of this channel: itself, or (shared slots) prim 0's channel at
                    // the same position.
                    uint32_t drv = c;
                    if (g.shared && p > 0) {
                        size_t i = (size_t)(std::find(g.channels[p].begin(), g.channels[p].end(), c) - g.channels[p].begin());
                        drv = g.channels[0][i];
                    }
                    nlohmann::json jc, targets = nlohmann::json::array(), fws = nlohmann::json::array(), names = nlohmann::json::array();
                    for (uint32_t k = 0; k < ch.target_count; ++k) {
                        for (size_t s = 0; s < g.slots.size(); ++s)
                            if (g.drivers[g.slots[s].driver] == drv && g.slots[s].target == k) { targets.push_back(s); used[s] = true; }
                        fws.push_back(ch.targets[k].full_weight);
                        names.push_back(ch.targets[k].name ? ch.targets[k].name : "");
                    }
                    jc["name"] = ch.name ? ch.name : "";
                    jc["targets"] = targets;
                    jc["full_weights"] = fws;
                    jc["target_names"] = names;
                    if (ch.origin && ch.origin[0]) jc["origin"] = ch.origin;
                    chans.push_back(jc);
                }
                e["channels"] = chans;
                nlohmann::json unused = nlohmann::json::array();
                for (size_t s = 0; s < used.size(); ++s)
                    if (!used[s]) unused.push_back(s);
                if (!unused.empty()) e["unused_targets"] = unused;
                bool identity = m.control_point_count == m.vertex_count;
                for (uint32_t v = 0; identity && m.control_points && v < m.vertex_count; ++v) identity = m.control_points[v] == v;
                if (!identity && m.control_points) {
                    nlohmann::json map = nlohmann::json::array();
                    for (uint32_t v = 0; v < m.vertex_count; ++v) map.push_back(m.control_points[v]);
                    e["control_points"] = {{"count", m.control_point_count}, {"map", map}};
                }
                meshes.push_back(e);
            }
        }
        nlohmann::json clips = nlohmann::json::array();
        for (uint32_t c = 0; c < raw->clip_count && exported_clips; ++c)
            clips.push_back({{"name", raw->clips[c].name ? raw->clips[c].name : ""}, {"start", raw->clips[c].start},
                             {"duration", raw->clips[c].duration}});
        return {{"format", "morphkit-gltf-channels"}, {"version", 1}, {"meshes", meshes}, {"clips", clips}};
    }

    void build()
    {
        model.asset.version = "2.0";
        model.asset.generator = "morphkit export";
        model.buffers.resize(1);
        plan_groups();
        int node_count = 0;
        for (const Group &g : groups) node_count = std::max(node_count, g.node + 1);
        model.nodes.resize(node_count);
        // Node indices of the source are kept, so unused ones become empty nodes; tinygltf
        // writes a node without any property as null, so give them a name.
        for (tinygltf::Node &n : model.nodes) n.name = "empty";
        tinygltf::Scene scene;
        for (int n = 0; n < node_count; ++n) scene.nodes.push_back(n);
        model.scenes.push_back(scene);
        model.defaultScene = 0;
        for (size_t gi = 0; gi < groups.size(); ++gi) {
            const Group &g = groups[gi];
            tinygltf::Mesh gm;
            const mk_raw_mesh &first = raw->meshes[g.prims[0]];
            gm.name = first.name ? first.name : "";
            for (size_t p = 0; p < g.prims.size(); ++p) export_primitive(g, p, gm);
            tinygltf::Value::Array names;
            std::vector<float> u;
            for (const Slot &s : g.slots) names.push_back(tinygltf::Value(slot_name(g, s)));
            for (const Slot &s : g.slots) {
                uint32_t c = g.drivers[s.driver];
                slot_weights(c, raw->channels[c].default_weight, u);
                gm.weights.push_back(u[s.target]);
            }
            if (!g.slots.empty()) {
                tinygltf::Value::Object extras;
                extras["targetNames"] = tinygltf::Value(names);
                gm.extras = tinygltf::Value(extras);
            }
            model.meshes.push_back(gm);
            tinygltf::Node &node = model.nodes[g.node];
            node.name = gm.name;
            node.mesh = (int)model.meshes.size() - 1;
            bool identity = true;
            for (int k = 0; k < 16; ++k) identity &= first.world[k] == ((k % 5) == 0 ? 1.0f : 0.0f);
            if (!identity) node.matrix.assign(first.world, first.world + 16);
            rep.meshes += (uint32_t)g.prims.size();
        }
        for (uint32_t c = 0; c < raw->clip_count; ++c) {
            tinygltf::Animation anim;
            anim.name = raw->clips[c].name ? raw->clips[c].name : "";
            for (const Group &g : groups) export_clip(c, g, g.node, anim);
            if (anim.channels.empty()) {
                // glTF requires at least one channel; keep the animation index aligned with
                // the clip index by animating the first morph node with its default weights.
                for (const Group &g : groups) {
                    if (g.slots.empty()) continue;
                    std::vector<float> t{raw->clips[c].start}, v;
                    std::vector<float> u;
                    for (const Slot &s : g.slots) {
                        slot_weights(g.drivers[s.driver], raw->channels[g.drivers[s.driver]].default_weight, u);
                        v.push_back(u[s.target]);
                    }
                    tinygltf::AnimationSampler smp;
                    smp.input = add_floats(t.data(), 1, 1, TINYGLTF_TYPE_SCALAR, 0, true);
                    smp.output = add_floats(v.data(), v.size(), 1, TINYGLTF_TYPE_SCALAR, 0, false);
                    anim.samplers.push_back(smp);
                    tinygltf::AnimationChannel ch;
                    ch.sampler = 0;
                    ch.target_node = g.node;
                    ch.target_path = "weights";
                    anim.channels.push_back(ch);
                    break;
                }
            }
            if (!anim.channels.empty()) { model.animations.push_back(anim); rep.clips++; }
        }
        exported_clips = rep.clips == raw->clip_count;
        model.buffers[0].name = "";
    }
};

bool ends_with(const std::string &s, const char *suffix)
{
    size_t n = std::strlen(suffix);
    if (s.size() < n) return false;
    std::string tail = s.substr(s.size() - n);
    std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return (char)std::tolower(c); });
    return tail == suffix;
}

mk_result run(const mk_raw_asset *raw, mk_gltf_container container, mk_arena *arena, void **gltf, size_t *gltf_size,
              char **sidecar, size_t *sidecar_size, mk_gltf_export_report *report, mk_error *err)
{
    mk_result r = mk_raw_validate(raw, err);
    if (r != MK_OK) return r;
    bool glb = container == MK_GLTF_GLB;
    Exporter ex;
    ex.raw = raw;
    ex.build();
    if (ex.buf().empty()) ex.buf().push_back(0);   // a buffer must have byteLength >= 1
    while (ex.buf().size() % 4) ex.buf().push_back(0);
    tinygltf::TinyGLTF writer;
    std::ostringstream out;
    if (!writer.WriteGltfSceneToStream(&ex.model, out, !glb, glb))
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "glTF export: tinygltf could not serialize the model");
    std::string bytes = out.str();
    void *g = mk_arena_alloc(arena, bytes.size());
    if (!g) return mk_error_oom(err, "glTF export");
    memcpy(g, bytes.data(), bytes.size());
    if (sidecar) {
        std::string text = ex.sidecar_json().dump();
        text.push_back('\n');
        char *t = mk_arena_strndup(arena, text.data(), text.size());
        if (!t) return mk_error_oom(err, "glTF export");
        *sidecar = t;
        *sidecar_size = text.size();
    }
    *gltf = g;
    *gltf_size = bytes.size();
    if (report) *report = ex.rep;
    return MK_OK;
}

} // namespace

extern "C" mk_result mk_export_gltf_memory(const mk_raw_asset *raw, mk_gltf_container container, mk_arena *arena,
                                           void **gltf, size_t *gltf_size, char **sidecar, size_t *sidecar_size,
                                           mk_gltf_export_report *report, mk_error *err)
{
    if (!raw || !arena || !gltf || !gltf_size || (sidecar && !sidecar_size) || (unsigned)container > MK_GLTF_JSON)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "glTF export: invalid argument");
    try {
        return run(raw, container, arena, gltf, gltf_size, sidecar, sidecar_size, report, err);
    } catch (const std::bad_alloc &) {
        return mk_error_oom(err, "glTF export");
    } catch (const std::exception &e) {
        return mk_error_set(err, MK_ERROR_IO, UINT64_MAX, "glTF export: %s", e.what());
    }
}

extern "C" mk_result mk_export_gltf(const mk_raw_asset *raw, const char *path, const char *sidecar_path,
                                    mk_gltf_export_report *report, mk_error *err)
{
    if (!raw || !path) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "glTF export: invalid argument");
    std::string p(path);
    bool glb = ends_with(p, ".glb");
    if (!glb && !ends_with(p, ".gltf"))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%.200s: the output must end in .glb or .gltf", path);
    mk_output outs[2] = {};
    outs[0].path = path;
    outs[1].path = sidecar_path;
    uint32_t count = sidecar_path ? 2 : 1;
    for (uint32_t i = 0; i < count; i++) {
        mk_result r = mk_output_check(&outs[i], nullptr, 0, err);
        if (r != MK_OK) return r;
    }
    mk_arena arena;
    mk_arena_init(&arena, nullptr);
    void *gltf = nullptr;
    char *sidecar = nullptr;
    size_t gltf_size = 0, sidecar_size = 0;
    mk_result r = mk_export_gltf_memory(raw, glb ? MK_GLTF_GLB : MK_GLTF_JSON, &arena, &gltf, &gltf_size,
                                        sidecar_path ? &sidecar : nullptr, &sidecar_size, report, err);
    if (r == MK_OK) {
        outs[0].data = gltf;
        outs[0].size = gltf_size;
        outs[1].data = sidecar;
        outs[1].size = sidecar_size;
        r = mk_write_outputs(outs, count, err);
    }
    mk_arena_free_all(&arena);
    return r;
}
