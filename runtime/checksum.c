/* SPDX-License-Identifier: MIT */
/* mk_checksum: a 64-bit hash over little-endian 8-byte words, four independent lanes so it
 * runs near memory speed (opening validates it in the same O(size) pass as everything else).
 * It detects corruption, it is not a cryptographic hash. docs/format.md gives the algorithm:
 *   lane[i] = seed_i; for word j: lane[j % 4] = rotl(lane[j % 4] ^ (w_j * K1), 31) * K2
 *   tail bytes are zero-padded into a last word; h = fold of the lanes with the size. */
#include <string.h>
#include "format.h"
#include "determinism.h"

#define K1 0x9E3779B185EBCA87ull
#define K2 0xC2B2AE3D27D4EB4Full

static uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

static uint64_t load64(const unsigned char *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    v = __builtin_bswap64(v);
#endif
    return v;
}

static uint64_t mix(uint64_t lane, uint64_t word) { return rotl(lane ^ (word * K1), 31) * K2; }

uint64_t mk_checksum(const void *data, uint64_t size)
{
    const unsigned char *p = data;
    uint64_t lane[4] = { K1, K2, K1 ^ K2, K1 + K2 };
    uint64_t i = 0;
    for (; i + 32 <= size; i += 32) {
        lane[0] = mix(lane[0], load64(p + i));
        lane[1] = mix(lane[1], load64(p + i + 8));
        lane[2] = mix(lane[2], load64(p + i + 16));
        lane[3] = mix(lane[3], load64(p + i + 24));
    }
    unsigned w = 0;
    for (; i + 8 <= size; i += 8) lane[w] = mix(lane[w], load64(p + i)), w++;
    if (i < size) {
        unsigned char tail[8] = { 0 };
        memcpy(tail, p + i, (size_t)(size - i));
        lane[w] = mix(lane[w], load64(tail));
    }
    uint64_t h = size * K2;
    for (int k = 0; k < 4; k++) h = mix(h ^ lane[k], lane[k] >> 29);
    h ^= h >> 33;
    h *= K1;
    h ^= h >> 29;
    return h;
}
