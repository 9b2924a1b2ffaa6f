/* SPDX-License-Identifier: MIT */
/* EXT_meshopt_compression filters, written from the extension README's Appendix B (see
 * gltf_meshopt.h for how its pseudo-code is read: the formula's value in double, rounded half
 * away from zero). */
#include <math.h>
#include <string.h>
#include "gltf_meshopt.h"

static int16_t load16(const uint8_t *p) { return (int16_t)(uint16_t)(p[0] | p[1] << 8); }
static void store16(uint8_t *p, int v) { p[0] = (uint8_t)(v & 0xff); p[1] = (uint8_t)((v >> 8) & 0xff); }

/* round(v) as the README writes it (half away from zero), clamped to [-max, max] so invalid
 * inputs cannot overflow the component (NaN, only from invalid inputs, becomes 0). */
static int round_clamped(double v, double max)
{
    if (v != v) return 0;
    if (v > max) v = max;
    if (v < -max) v = -max;
    return (int)round(v);
}

/* The README's octahedral decode of one vector: in = x, y and the K-bit 1.0; max = INTN_MAX. */
static void octahedral(const int in[3], int out[3], double max)
{
    double one = in[2];
    double x = in[0] / one;
    double y = in[1] / one;
    double z = 1.0 - fabs(x) - fabs(y);
    double t = fmin(z, 0.0);                 /* octahedral fixup for the negative hemisphere */
    x -= copysign(t, x);
    y -= copysign(t, y);
    double len = sqrt(x * x + y * y + z * z);
    out[0] = round_clamped(x / len * max, max);
    out[1] = round_clamped(y / len * max, max);
    out[2] = round_clamped(z / len * max, max);
}

void mk_meshopt_filter_octahedral(void *data, size_t count, size_t stride)
{
    uint8_t *p = data;
    if (stride == 4) {
        for (size_t i = 0; i < count; i++, p += 4) {
            int in[3] = { (int8_t)p[0], (int8_t)p[1], (int8_t)p[2] }, out[3];
            octahedral(in, out, 127.0);
            for (int c = 0; c < 3; c++) p[c] = (uint8_t)(out[c] & 0xff);   /* p[3] passes through */
        }
    } else if (stride == 8) {
        for (size_t i = 0; i < count; i++, p += 8) {
            int in[3] = { load16(p), load16(p + 2), load16(p + 4) }, out[3];
            octahedral(in, out, 32767.0);
            for (int c = 0; c < 3; c++) store16(p + 2 * c, out[c]);         /* p[6..7] passes through */
        }
    }
}

void mk_meshopt_filter_quaternion(void *data, size_t count, size_t stride)
{
    if (stride != 8) return;
    const double range = 1.0 / sqrt(2.0);
    uint8_t *p = data;
    for (size_t i = 0; i < count; i++, p += 8) {
        int w3 = load16(p + 6);
        double one = w3 | 3;                 /* K-bit 1.0 but for the bottom two bits */
        double x = load16(p) / one * range;
        double y = load16(p + 2) / one * range;
        double z = load16(p + 4) / one * range;
        double w = sqrt(fmax(0.0, 1.0 - x * x - y * y - z * z));
        int maxcomp = w3 & 3;                /* a cyclic rotation of the components */
        store16(p + 2 * ((maxcomp + 1) % 4), round_clamped(x * 32767.0, 32767.0));
        store16(p + 2 * ((maxcomp + 2) % 4), round_clamped(y * 32767.0, 32767.0));
        store16(p + 2 * ((maxcomp + 3) % 4), round_clamped(z * 32767.0, 32767.0));
        store16(p + 2 * ((maxcomp + 0) % 4), round_clamped(w * 32767.0, 32767.0));
    }
}

void mk_meshopt_filter_exponential(void *data, size_t count, size_t stride)
{
    if (stride == 0 || stride % 4 != 0) return;
    uint8_t *p = data;
    for (size_t i = 0; i < count * (stride / 4); i++, p += 4) {
        uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        int32_t e = (int32_t)(u >> 24);
        if (e >= 128) e -= 256;                        /* input >> 24, arithmetic */
        int32_t m = (int32_t)(u & 0xffffffu);
        if (m >= 0x800000) m -= 0x1000000;             /* (input << 8) >> 8 */
        /* 2^e * m: exact in float32 for the valid range (|m| < 2^23, |e| <= 100). */
        float f = (float)ldexp((double)m, e);
        uint32_t bits;
        memcpy(&bits, &f, 4);
        p[0] = (uint8_t)bits; p[1] = (uint8_t)(bits >> 8); p[2] = (uint8_t)(bits >> 16); p[3] = (uint8_t)(bits >> 24);
    }
}
