/* SPDX-License-Identifier: MIT */
/* The .morph blob layout, version 5 (docs/format.md is the prose description).
 *
 * Little-endian. Every record and array starts at a multiple of 16 bytes from the blob start.
 * Offsets are absolute byte offsets from the blob start. Strings are offsets into the STRINGS
 * section (NUL-terminated; the section ends with a NUL).
 *
 *   header (64 B) | section table (section_count x 32 B) | sections ...
 *
 * Shared by the runtime (reader) and the offline writer; nothing here allocates.
 */
#ifndef MK_FORMAT_H
#define MK_FORMAT_H

#include <stdint.h>

#define MK_MAGIC "MORPHKIT"
#define MK_BLOCK_SIZE 64u          /* vertices per block: one uint64 mask bit per vertex */
#define MK_ALIGN 16u
#define MK_MAX_VERTICES (UINT32_MAX - (MK_BLOCK_SIZE - 1))   /* per mesh: 2^32 - 64 */

enum {
    MK_SECTION_STRINGS = 1,        /* char[] */
    MK_SECTION_MESHES = 2,         /* mk_blob_mesh[] */
    MK_SECTION_CHANNELS = 3,       /* mk_blob_channel[] */
    MK_SECTION_TARGETS = 4,        /* mk_blob_target[] */
    MK_SECTION_CLIPS = 5,          /* mk_blob_clip[] */
    MK_SECTION_TRACKS = 6,         /* mk_blob_track[] */
    MK_SECTION_KEYS = 7,           /* mk_key[] */
    MK_SECTION_DATA = 8,           /* bulk arrays referenced by meshes */
    MK_SECTION_KIND_COUNT = 9
};

typedef struct mk_blob_header {
    char magic[8];                 /* "MORPHKIT" */
    uint32_t version;              /* MK_FORMAT_VERSION */
    uint32_t header_size;          /* 64 */
    uint64_t file_size;            /* whole blob in bytes */
    uint64_t checksum;             /* mk_checksum of bytes [32, file_size) */
    uint32_t section_count;
    uint32_t flags;                /* zero */
    uint32_t reserved[6];          /* zero */
} mk_blob_header;

typedef struct mk_blob_section {
    uint32_t kind;                 /* MK_SECTION_* (each at most once) */
    uint32_t element_size;         /* bytes per element (1 for STRINGS and DATA) */
    uint64_t count;                /* elements */
    uint64_t offset;               /* absolute, 16-aligned */
    uint64_t size;                 /* bytes = count * element_size */
} mk_blob_section;

enum {
    MK_MESH_HAS_NORMALS = 1u,
    MK_MESH_HAS_TANGENTS = 2u
};

typedef struct mk_blob_mesh {
    uint32_t name;                 /* string */
    uint32_t vertex_count;
    uint32_t control_point_count;
    uint32_t triangle_count;
    uint32_t first_channel, channel_count;   /* contiguous range of the asset's channels */
    uint32_t first_target, target_count;     /* contiguous range of the asset's targets */
    uint32_t stacking;             /* MK_STACKING_ADDITIVE or MK_STACKING_SEQUENTIAL */
    uint32_t flags;                /* MK_MESH_HAS_* */
    int32_t gltf_node, gltf_mesh, gltf_primitive;
    uint32_t block_count;          /* ceil(vertex_count / 64) */
    uint32_t reserved[2];
    float world[16];               /* column-major */
    uint64_t positions;            /* float[3 * vertex_count] */
    uint64_t normals;              /* float[3 * vertex_count] or 0 */
    uint64_t tangents;             /* float[4 * vertex_count] or 0 */
    uint64_t triangles;            /* uint32[3 * triangle_count] or 0 */
    uint64_t control_points;       /* uint32[vertex_count] */
    uint64_t block_entries;        /* uint32[block_count + 1]: first entry of each block */
    uint64_t entries;              /* mk_blob_entry[entry_count] */
    uint64_t entry_count;
    uint64_t target_data;          /* start of this mesh's delta data */
    uint64_t target_data_size;     /* bytes */
} mk_blob_mesh;                    /* 208 bytes */

typedef struct mk_blob_channel {
    uint32_t name, origin;         /* strings */
    uint32_t mesh;
    uint32_t first_target;         /* asset target index; targets in increasing full weight */
    uint32_t target_count;         /* >= 1 */
    float default_weight;
    uint32_t reserved[2];
} mk_blob_channel;                 /* 32 bytes */

enum {
    MK_TARGET_QUANTIZED = 1u,      /* has packed entries: integers times the per-attribute step */
    MK_TARGET_HAS_NORMALS = 2u,
    MK_TARGET_HAS_TANGENTS = 4u
};

typedef struct mk_blob_target {
    uint32_t name;                 /* string */
    uint32_t channel;              /* asset channel index */
    float full_weight;             /* nonzero; strictly increasing within the channel */
    uint32_t flags;                /* MK_TARGET_* */
    float position_scale;          /* step of packed values (quantized targets), else 0 */
    float normal_scale;
    float tangent_scale;
    uint32_t moved_vertices;
} mk_blob_target;                  /* 32 bytes */

/* One target's data for one block of 64 vertices (docs/format.md, "Blocks and entries").
 *
 * An entry is a 16-byte head (mk_blob_entry) followed by its packing: a width code per
 * component (4 bits, component k in byte k / 2, low nibble first; 0-14 = that many bits, 15 =
 * 16 bits), then an int16 offset per component (in steps of its attribute). Components are the
 * mesh's attributes' x, y, z in order positions, normals (mesh with normals), tangents (mesh
 * with tangents), so an entry is mk_entry_stride(mesh flags) bytes: 24, 32 or 40.
 *
 * A packed entry's data (4-byte aligned, at mesh.target_data + 4 x data) holds, with m =
 * popcount(mask) and after the 12-byte position offsets of an MK_ENTRY_WIDE entry, each
 * component's m unsigned values u of its width w, in mask-bit order, least significant bit
 * first, each component from a byte boundary (ceil(m w / 8) bytes); component k of the j-th
 * vertex is (offset_k + u) x the target's step of that attribute (position_scale, normal_scale,
 * tangent_scale). Width 0 stores nothing: every vertex has the offset. An MK_ENTRY_FLOAT entry
 * holds float32 xyz triples instead, interleaved (x0 y0 z0 x1 ...), positions, then normal
 * deltas (target with normals), then tangent deltas (target with tangents); its codes and
 * offsets are zero. A mesh's target data ends at least MK_TARGET_DATA_TAIL bytes after its
 * last entry's data, so a decoder may load 16 bytes at any byte of an entry's data. */
#define MK_ENTRY_TARGET_MASK 0x00FFFFFFu   /* target_and_flags: the mesh-local target index */
#define MK_MAX_MESH_TARGETS (MK_ENTRY_TARGET_MASK + 1u)   /* targets per mesh: 2^24 */
#define MK_ENTRY_FLOAT 0x80000000u       /* target_and_flags: the entry's data is float32 */
/* target_and_flags: a packed entry whose position offsets are int32, the first 12 bytes of its
 * data (x, y, z; |offset| <= MK_WIDE_OFFSET_MAX), in place of the head's (which are zero). */
#define MK_ENTRY_WIDE 0x40000000u
#define MK_ENTRY_WIDE_BYTES 12u
#define MK_WIDE_OFFSET_MAX 0x7FFFFF          /* 2^23 - 1: offset + u stays exact in float32 */
#define MK_ENTRY_FLAGS_KNOWN (MK_ENTRY_FLOAT | MK_ENTRY_WIDE)
#define MK_ENTRY_HEAD 16u                    /* bytes before the width codes */
#define MK_MAX_WIDTH 16u                     /* bits per value */
#define MK_WIDTH_CODE_16 15u                 /* the code of width 16 */
#define MK_DATA_UNIT 4u                      /* entry.data counts 4-byte units */
#define MK_TARGET_DATA_TAIL 16u
#define MK_MAX_COMPONENTS 9u                 /* positions, normals, tangents: xyz each */
#define MK_ENTRY_MAX_BYTES 40u               /* mk_entry_stride with normals and tangents */

typedef struct mk_blob_entry {
    uint32_t target_and_flags;     /* mesh-local target index (low 24 bits) | MK_ENTRY_* */
    uint32_t data;                 /* offset from mesh.target_data, in 4-byte units */
    uint64_t mask;                 /* bit i: vertex block*64 + i has data */
    /* then uint8_t codes[mk_entry_code_bytes], int16_t offsets[components] */
} mk_blob_entry;                   /* the 16-byte head of an entry */

typedef struct mk_blob_clip {
    uint32_t name;
    uint32_t first_track, track_count;
    float start, duration;         /* seconds */
    uint32_t reserved[3];
} mk_blob_clip;                    /* 32 bytes */

typedef struct mk_blob_track {
    uint32_t channel;              /* asset channel index */
    uint32_t first_key, key_count; /* key_count >= 1; times strictly increasing */
    uint32_t reserved;
} mk_blob_track;                   /* 16 bytes */

/* Smallest |full weight| and smallest gap between a channel's key points (including the
 * implicit 0): keeps span parameters finite for any reasonable weight. */
/* MK_MIN_FULL_WEIGHT_GAP is public (morphkit.h). */

/* Bit helpers with a portable fallback (the runtime must build with any C11 compiler). */
static inline uint32_t mk_popcount64(uint64_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return (uint32_t)__builtin_popcountll(x);
#else
    uint32_t n = 0;
    while (x) { x &= x - 1; n++; }
    return n;
#endif
}

/* Index of the lowest set bit; x must be nonzero. */
static inline unsigned mk_ctz64(uint64_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return (unsigned)__builtin_ctzll(x);
#else
    unsigned n = 0;
    while (!(x & 1)) { x >>= 1; n++; }
    return n;
#endif
}

/* 64-bit checksum (documented in docs/format.md). */
uint64_t mk_checksum(const void *data, uint64_t size);

static inline uint32_t mk_entry_target(const mk_blob_entry *e) { return e->target_and_flags & MK_ENTRY_TARGET_MASK; }
static inline int mk_entry_packed(const mk_blob_entry *e) { return (e->target_and_flags & MK_ENTRY_FLOAT) == 0; }
static inline int mk_entry_wide(const mk_blob_entry *e) { return (e->target_and_flags & MK_ENTRY_WIDE) != 0; }

/* Components of a mesh's entries: 3 per attribute the mesh has. */
static inline uint32_t mk_mesh_components(uint32_t mesh_flags)
{
    return 3u * (1u + ((mesh_flags & MK_MESH_HAS_NORMALS) ? 1u : 0u) + ((mesh_flags & MK_MESH_HAS_TANGENTS) ? 1u : 0u));
}

/* Bytes of the width codes (4 bits per component, rounded up to an even count of bytes). */
static inline uint32_t mk_entry_code_bytes(uint32_t components) { return (components + 3u) / 4u * 2u; }

/* Bytes of one entry of a mesh: 24 (positions), 32 (and normals) or 40 (and tangents). */
static inline uint32_t mk_entry_stride(uint32_t mesh_flags)
{
    const uint32_t c = mk_mesh_components(mesh_flags);
    return MK_ENTRY_HEAD + mk_entry_code_bytes(c) + 2u * c;
}

/* The first component of an attribute (0 positions, 1 normals, 2 tangents) in a mesh's
 * entries; the attribute must be one the mesh has. */
static inline uint32_t mk_attribute_component(uint32_t mesh_flags, uint32_t attribute)
{
    if (attribute == 0) return 0;
    if (attribute == 1) return 3;
    return (mesh_flags & MK_MESH_HAS_NORMALS) ? 6u : 3u;
}

/* Entry e of a mesh's entry array (stride from mk_entry_stride). */
static inline const mk_blob_entry *mk_entry_at(const uint8_t *entries, uint32_t stride, uint64_t e)
{
    return (const mk_blob_entry *)(const void *)(entries + e * stride);
}

/* The width code of component k (0-15). */
static inline uint32_t mk_entry_code(const mk_blob_entry *e, uint32_t k)
{
    const uint8_t *codes = (const uint8_t *)e + MK_ENTRY_HEAD;
    return (uint32_t)(codes[k >> 1] >> (4u * (k & 1u))) & 15u;
}

static inline uint32_t mk_width_of_code(uint32_t code) { return code == MK_WIDTH_CODE_16 ? 16u : code; }
static inline uint32_t mk_code_of_width(uint32_t width) { return width == 16u ? MK_WIDTH_CODE_16 : width; }

/* The int16 offset of component k (components = mk_mesh_components of the mesh). */
static inline int32_t mk_entry_offset(const mk_blob_entry *e, uint32_t components, uint32_t k)
{
    const uint8_t *p = (const uint8_t *)e + MK_ENTRY_HEAD + mk_entry_code_bytes(components) + 2u * k;
    return (int16_t)(uint16_t)(p[0] | (uint32_t)p[1] << 8);
}

/* Little-endian reads of a packed entry's bytes. */
static inline uint32_t mk_load_u32le(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Value j (0-based rank in the mask) of a component whose packed bits start at p, width w
 * (0-16): reads 4 bytes from byte j w / 8. */
static inline uint32_t mk_unpack(const uint8_t *p, uint32_t w, uint32_t j)
{
    const uint32_t bit = j * w;
    return (mk_load_u32le(p + (bit >> 3)) >> (bit & 7u)) & ((1u << w) - 1u);
}

/* Bytes of one component's packed values: m values of w bits. */
static inline uint64_t mk_packed_bytes(uint32_t m, uint32_t w) { return ((uint64_t)m * w + 7u) / 8u; }

/* Where a packed entry's components lie (docs/format.md): per component its first byte, width
 * and offset (a WIDE entry's position offsets from its data), read once per entry by every
 * decoder (the evaluation, the blob reader). */
typedef struct mk_packed_layout {
    uint32_t m;                                /* values per component: popcount(mask) */
    const uint8_t *at[MK_MAX_COMPONENTS];
    uint32_t width[MK_MAX_COMPONENTS];
    int32_t offset[MK_MAX_COMPONENTS];
} mk_packed_layout;

/* Fills l for a packed entry whose data starts at data; components = mk_mesh_components of the
 * mesh. Returns the data's bytes (every component's, the WIDE offsets included). */
static inline uint64_t mk_packed_layout_of(mk_packed_layout *l, const mk_blob_entry *e, uint32_t components,
                                           const uint8_t *data)
{
    const uint8_t *p = data + (mk_entry_wide(e) ? MK_ENTRY_WIDE_BYTES : 0u);
    l->m = mk_popcount64(e->mask);
    for (uint32_t k = 0; k < components; k++) {
        const uint32_t w = mk_width_of_code(mk_entry_code(e, k));
        l->at[k] = p;
        l->width[k] = w;
        l->offset[k] = k < 3 && mk_entry_wide(e) ? (int32_t)mk_load_u32le(data + 4u * k) : mk_entry_offset(e, components, k);
        p += mk_packed_bytes(l->m, w);
    }
    return (uint64_t)(p - data);
}

/* Bytes of a stored entry's data (before its padding to 4 bytes) that hold the attributes in
 * target_flags (MK_TARGET_HAS_*; positions always): packed, the WIDE offsets and those
 * attributes' components (the codes of attributes a target lacks are zero, so its own flags
 * give the whole entry); float, m triples per attribute. */
static inline uint64_t mk_entry_bytes(const mk_blob_entry *e, uint32_t mesh_flags, uint32_t target_flags)
{
    const uint32_t m = mk_popcount64(e->mask);
    const int normals = (target_flags & MK_TARGET_HAS_NORMALS) != 0, tangents = (target_flags & MK_TARGET_HAS_TANGENTS) != 0;
    if (!mk_entry_packed(e)) return (1u + (uint64_t)normals + (uint64_t)tangents) * 12u * m;
    uint64_t n = mk_entry_wide(e) ? MK_ENTRY_WIDE_BYTES : 0u;
    for (uint32_t a = 0; a < 3; a++) {
        if ((a == 1 && !normals) || (a == 2 && !tangents)) continue;
        const uint32_t k0 = mk_attribute_component(mesh_flags, a);
        for (uint32_t k = k0; k < k0 + 3; k++) n += mk_packed_bytes(m, mk_width_of_code(mk_entry_code(e, k)));
    }
    return n;
}

#endif
