// SPDX-License-Identifier: MIT
// morphkit's evaluation of one mesh on the GPU (docs/gpu.md): the same blob, the same rules as
// the CPU runtime (docs/semantics.md). One workgroup per 64-vertex block, one invocation per
// vertex. The block's entries (docs/format.md: one per target with data in the block, sorted by
// target) are read by the whole workgroup in the same order, so control flow stays uniform
// except for the mask bit of each vertex. The frame's plan (mk_gpu_plan_run) gives each
// target's coefficient and, for slerp normals, each channel's span; the shader only adds.
#version 450

layout(local_size_x = 64) in;

// The mesh's arrays, addressed in 32-bit words from the start of the bound window (the host
// binds the part of the blob that holds them).
layout(std430, set = 0, binding = 0) readonly buffer Data { uint data[]; };
// The mesh's target records (32 bytes each: name, channel, full_weight, flags, scales, moved).
layout(std430, set = 0, binding = 1) readonly buffer Targets { uint targets[]; };
// The frame's plan: coef[T] | slerp_channel[T] | spans[C], each part 16-byte aligned.
layout(std430, set = 0, binding = 2) readonly buffer Plan { uint plan[]; };
// Outputs: 32-bit words at the engine's offsets and strides.
layout(std430, set = 0, binding = 3) writeonly buffer OutPositions { float out_positions[]; };
layout(std430, set = 0, binding = 4) writeonly buffer OutNormals { float out_normals[]; };
layout(std430, set = 0, binding = 5) writeonly buffer OutTangents { float out_tangents[]; };

layout(push_constant) uniform Params {
    uint positions;       // word offsets into Data
    uint normals;
    uint tangents;
    uint block_table;
    uint entries;
    uint target_data;
    uint first_target;    // word offset into Targets of the mesh's first target record
    uint vertex_count;
    uint target_count;
    uint block_count;
    uint flags;           // 1: write normals, 2: write tangents
    uint groups_x;        // workgroups per row of the dispatch
    uint out_p, out_p_stride;  // words
    uint out_n, out_n_stride;
    uint out_t, out_t_stride;
    uint entry_words;     // words of one entry: mk_entry_stride of the mesh's flags / 4
    uint components;      // the mesh's entry components: mk_mesh_components
    uint mesh_flags;      // MK_MESH_HAS_*
} pc;

const uint ENTRY_FLOAT = 0x80000000u;
const uint ENTRY_WIDE = 0x40000000u;
const uint ENTRY_TARGET_MASK = 0x00FFFFFFu;
const uint MESH_HAS_NORMALS = 1u;
const uint TARGET_HAS_NORMALS = 2u;
const uint TARGET_HAS_TANGENTS = 4u;
const uint WANT_NORMALS = 1u;
const uint WANT_TANGENTS = 2u;

vec3 load3(uint w)
{
    return vec3(uintBitsToFloat(data[w]), uintBitsToFloat(data[w + 1u]), uintBitsToFloat(data[w + 2u]));
}

// What the whole workgroup reads once from an entry (runtime/format.h, mk_blob_entry).
struct Entry {
    uint head;     // word of the entry's head: target_and_flags, data, mask, then codes and offsets
    uint at;       // word of its data (the data field counts 4-byte units)
    bool packed;   // else float32 triples
    bool wide;     // a packed entry whose position offsets are the first 3 words of its data
    uint m;        // vertices in its mask
    uint tflags;   // its target's MK_TARGET_* flags
};

// The first component of attribute a (0 positions, 1 normals, 2 tangents) in the mesh's
// entries, as mk_attribute_component.
uint attribute_component(uint a)
{
    if (a == 0u) return 0u;
    if (a == 1u) return 3u;
    return (pc.mesh_flags & MESH_HAS_NORMALS) != 0u ? 6u : 3u;
}

// Bits per value of component k: its 4-bit code after the 16-byte head, low nibble first.
uint entry_width(uint head, uint k)
{
    uint code = bitfieldExtract(data[head + 4u + (k >> 3u)], int(4u * (k & 7u)), 4);
    return code == 15u ? 16u : code;
}

// The int16 offset of component k, after the codes (an even count of bytes, so an offset never
// straddles a word).
int entry_offset(uint head, uint k)
{
    uint byte = 16u + (pc.components + 3u) / 4u * 2u + 2u * k;
    return bitfieldExtract(int(data[head + (byte >> 2u)]), int(8u * (byte & 2u)), 16);
}

// Value `rank` (w <= 16 bits) of a component whose values start `byte` bytes after word `at`.
// The start need not be word-aligned, so the value's bit address is split into a word and a bit
// within it (at + byte / 4 words, then (byte & 3) * 8 + rank * w bits: no 32-bit overflow of
// a bit address even in a 4 GiB window), and the value is cut from that word and the next. The
// 16 zero bytes after a mesh's last entry keep the second word inside the target data.
uint unpack(uint at, uint byte, uint w, uint rank)
{
    uint bit = 8u * (byte & 3u) + rank * w;
    uint word = at + (byte >> 2u) + (bit >> 5u);
    uint s = bit & 31u;
    uint low = data[word] >> s;
    // The next word's bits above the first's, shifted in two steps: s may be 0, and a shift by
    // 32 is undefined.
    uint high = (data[word + 1u] << 1u) << (31u - s);
    return (low | high) & ((1u << w) - 1u);
}

// The stored delta of one vertex: attribute `attr` (0 positions, 1 normals, 2 tangents; one
// the target has) of the vertex at `rank` among the entry's m vertices. Packed: offset + u
// per component, in steps of the attribute (applied by the caller); float: the float32 triple.
// This is the one place that decodes the block format.
vec3 entry_delta(Entry en, uint attr, uint rank)
{
    if (!en.packed) {
        // Triples of the target's attributes one after the other: positions, normals, tangents.
        uint slot = attr == 0u ? 0u : attr == 1u || (en.tflags & TARGET_HAS_NORMALS) == 0u ? 1u : 2u;
        return load3(en.at + 3u * (slot * en.m + rank));
    }
    // Components are stored one after the other, each from a byte boundary; the codes of the
    // attributes the target lacks are 0, so they take no bytes.
    uint k0 = attribute_component(attr);
    uint byte = en.wide ? 12u : 0u;
    for (uint k = 0u; k < k0; k++) byte += (en.m * entry_width(en.head, k) + 7u) >> 3u;
    vec3 d;
    for (uint c = 0u; c < 3u; c++) {
        uint k = k0 + c;
        uint w = entry_width(en.head, k);
        int offset = en.wide && k < 3u ? int(data[en.at + k]) : entry_offset(en.head, k);
        d[c] = float(offset + int(unpack(en.at, byte, w, rank)));
        byte += (en.m * w + 7u) >> 3u;
    }
    return d;
}

float plan_coef(uint t) { return uintBitsToFloat(plan[t]); }

uint plan_part() { return ((pc.target_count + 3u) & ~3u); }   // words of one per-target part

int plan_slerp_channel(uint t) { return int(plan[plan_part() + t]); }

// Word of channel c's span in the plan.
uint plan_span_at(int c) { return 2u * plan_part() + 4u * uint(c); }

// Span of channel c: target_a, target_b (-1: the implicit zero key), t, sequential scale.
void plan_span(int c, out int a, out int b, out float t, out float scale)
{
    uint w = plan_span_at(c);
    a = int(plan[w]);
    b = int(plan[w + 1u]);
    t = uintBitsToFloat(plan[w + 2u]);
    scale = uintBitsToFloat(plan[w + 3u]);
}

vec3 normalized_or(vec3 v, vec3 fallback)
{
    float len2 = dot(v, v);
    return len2 < 1e-16 ? fallback : v * (1.0 / sqrt(len2));
}

// sin and atan to float precision. Vulkan lets the built-ins err by 2^-11 (sin) and 4096 ulp
// (atan), and an extrapolated slerp multiplies an angle's error by |t|: these keep the GPU's
// normals within docs/gpu.md's tolerance of the CPU's.
const float PI = 3.14159265358979;

float sin_precise(float x)
{
    // x = k pi + r with |r| <= pi/2 (pi in two parts, so r is exact for the angles slerp makes).
    float k = floor(x * (1.0 / PI) + 0.5);
    float r = (x - k * 3.140625) - k * 9.67653589793e-4;
    float r2 = r * r;
    float p = r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 * (1.0 / 362880.0
                  + r2 * (-1.0 / 39916800.0)))));
    return mod(k, 2.0) == 0.0 ? p : -p;
}

// atan(y / x) in [0, pi] for y >= 0.
float atan2_precise(float y, float x)
{
    float ax = abs(x);
    bool swap = y > ax;
    float a = swap ? ax / y : (ax > 0.0 ? y / ax : 0.0);   // in [0, 1]
    float z = a / (1.0 + sqrt(1.0 + a * a));                 // atan(a) = 2 atan(z), z <= 0.4143
    float z2 = z * z;
    float t = z * (1.0 + z2 * (-1.0 / 3.0 + z2 * (1.0 / 5.0 + z2 * (-1.0 / 7.0 + z2 * (1.0 / 9.0 + z2 * (-1.0 / 11.0
                  + z2 * (1.0 / 13.0 + z2 * (-1.0 / 15.0))))))));
    float angle = 2.0 * t;
    if (swap) angle = 0.5 * PI - angle;
    return x < 0.0 ? PI - angle : angle;
}

// Slerp of unit vectors with the angle from atan2(|a x b|, a . b), as the CPU runtime does.
vec3 slerp3(vec3 a, vec3 b, float t)
{
    float d = dot(a, b);
    float s = length(cross(a, b));
    float wa, wb;
    if (s < 1e-6) { wa = 1.0 - t; wb = t; }
    else {
        float theta = atan2_precise(s, d);
        wa = sin_precise((1.0 - t) * theta) / s;
        wb = sin_precise(t * theta) / s;
    }
    return wa * a + wb * b;
}

// The slerped normal displacement of a channel's span for one vertex: slerp(n_a, n_b, t) minus
// the normalized base, times the span's sequential factor.
vec3 slerp_displacement(int channel, vec3 base_raw, vec3 delta_a, vec3 delta_b)
{
    int ta, tb;
    float t, scale;
    plan_span(channel, ta, tb, t, scale);
    vec3 base = normalized_or(base_raw, base_raw);
    vec3 na = ta >= 0 ? normalized_or(base_raw + delta_a, base) : base;
    vec3 nb = tb >= 0 ? normalized_or(base_raw + delta_b, base) : base;
    return scale * (slerp3(na, nb, t) - base);
}

void main()
{
    uint block = gl_WorkGroupID.x + gl_WorkGroupID.y * pc.groups_x;
    if (block >= pc.block_count) return;
    uint lane = gl_LocalInvocationID.x;
    uint v = block * 64u + lane;
    bool live = v < pc.vertex_count;
    bool want_n = (pc.flags & WANT_NORMALS) != 0u;
    bool want_t = (pc.flags & WANT_TANGENTS) != 0u;

    vec3 base_p = live ? load3(pc.positions + 3u * v) : vec3(0.0);
    vec3 base_n = live && want_n ? load3(pc.normals + 3u * v) : vec3(0.0);
    vec4 base_t = vec4(0.0);
    if (live && want_t) base_t = vec4(load3(pc.tangents + 4u * v), uintBitsToFloat(data[pc.tangents + 4u * v + 3u]));
    vec3 acc_p = base_p, acc_n = base_n, acc_t = base_t.xyz;

    // Slerp channels: a channel's targets are adjacent in the entry order, so its span's two
    // raw deltas are gathered while its entries pass, then blended once.
    int open_channel = -1, open_target_a = -1;   // the channel and its span's first target
    vec3 slerp_a = vec3(0.0), slerp_b = vec3(0.0);
    bool touched = false;

    // The lane's bit in the 64-bit mask (two words) and the bits below it.
    uint below_lo = lane < 32u ? (1u << lane) - 1u : 0xFFFFFFFFu;
    uint below_hi = lane < 32u ? 0u : (1u << (lane - 32u)) - 1u;

    uint e_end = data[pc.block_table + block + 1u];
    for (uint e = data[pc.block_table + block]; e < e_end; e++) {
        uint h = pc.entries + pc.entry_words * e;
        uint target_and_flags = data[h];
        uint ti = target_and_flags & ENTRY_TARGET_MASK;
        float c = plan_coef(ti);
        if (c == 0.0) continue;
        uint mask_lo = data[h + 2u], mask_hi = data[h + 3u];
        bool has = lane < 32u ? ((mask_lo >> lane) & 1u) != 0u : ((mask_hi >> (lane - 32u)) & 1u) != 0u;
        uint m = uint(bitCount(mask_lo) + bitCount(mask_hi));
        uint rank = uint(bitCount(mask_lo & below_lo) + bitCount(mask_hi & below_hi));
        uint tr = pc.first_target + 8u * ti;
        uint tflags = targets[tr + 3u];
        bool q = (target_and_flags & ENTRY_FLOAT) == 0u;
        float position_scale = q ? uintBitsToFloat(targets[tr + 4u]) : 1.0;
        float normal_scale = q ? uintBitsToFloat(targets[tr + 5u]) : 1.0;
        float tangent_scale = q ? uintBitsToFloat(targets[tr + 6u]) : 1.0;
        Entry en = Entry(h, pc.target_data + data[h + 1u], q, (target_and_flags & ENTRY_WIDE) != 0u, m, tflags);
        if (has) acc_p += (c * position_scale) * entry_delta(en, 0u, rank);
        if (want_n && (tflags & TARGET_HAS_NORMALS) != 0u) {
            int sc = plan_slerp_channel(ti);
            if (sc < 0) {
                if (has) acc_n += (c * normal_scale) * entry_delta(en, 1u, rank);
            } else {
                if (sc != open_channel) {
                    if (open_channel >= 0 && touched) acc_n += slerp_displacement(open_channel, base_n, slerp_a, slerp_b);
                    slerp_a = vec3(0.0);
                    slerp_b = vec3(0.0);
                    open_channel = sc;
                    open_target_a = int(plan[plan_span_at(sc)]);
                    touched = false;
                }
                if (has) {
                    vec3 d = normal_scale * entry_delta(en, 1u, rank);
                    if (int(ti) == open_target_a) slerp_a += d;
                    else slerp_b += d;
                    touched = true;
                }
            }
        }
        if (want_t && (tflags & TARGET_HAS_TANGENTS) != 0u && has)
            acc_t += (c * tangent_scale) * entry_delta(en, 2u, rank);
    }
    if (open_channel >= 0 && touched) acc_n += slerp_displacement(open_channel, base_n, slerp_a, slerp_b);

    if (!live) return;
    uint o = pc.out_p + v * pc.out_p_stride;
    out_positions[o] = acc_p.x;
    out_positions[o + 1u] = acc_p.y;
    out_positions[o + 2u] = acc_p.z;
    if (want_n) {
        vec3 n = normalized_or(acc_n, base_n);
        o = pc.out_n + v * pc.out_n_stride;
        out_normals[o] = n.x;
        out_normals[o + 1u] = n.y;
        out_normals[o + 2u] = n.z;
    }
    if (want_t) {
        vec3 t = normalized_or(acc_t, base_t.xyz);
        o = pc.out_t + v * pc.out_t_stride;
        out_tangents[o] = t.x;
        out_tangents[o + 1u] = t.y;
        out_tangents[o + 2u] = t.z;
        out_tangents[o + 3u] = base_t.w;
    }
}
