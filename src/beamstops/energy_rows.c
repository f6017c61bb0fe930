/* The energy sums of one scene (beamstops_band_solve's energy_dots, n >= 1): usu = u.su,
 * dsu = d.su and dmd = d.M d, each in eight partial sums (row j, from 0, in sum j mod 8) added as
 * ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)), a sum with no row 0 (n < 8). Row j's term
 * of d.M d is d_j (M_jj d_j + 2 t_j), t_j = fma(M_j-3,j, d_j-3, fma(M_j-1,j, d_j-1, M_j-2,j d_j-2)),
 * the neighbours before row 0 taken as 0: the operations gfortran makes of the lockstep lanes'
 * expression (beamstops_band_solve_lockstep's lockstep_energy_dots), so that a member's sums are
 * these, bit for bit (tests/fortran/test_lockstep.f90 checks it on every lane). The file is
 * built with -ffp-contract=off (meson.build): the compiler fuses none of the products and sums
 * written here, and those that gfortran fuses are written as fused (fmadd, or __builtin_fma where
 * the machine has FMA; where it has not, gfortran fuses none either).
 *
 * With AVX-512, eight rows are one vector operation, the first and last rows loaded under a mask:
 * about 190 instructions at n = 38 by its code (57 for the first eight rows, 18 a whole turn, 31
 * for the last rows, 30 for the three sums) where the Fortran rows took 283 (callgrind), the
 * largest part of the books of a recorded step (a record costs the step about in proportion to
 * its instructions: docs/performance_notes.md, "The Figure 4 run against its targets"). Without AVX-512 but with
 * AVX2 and FMA, the same operations four rows a vector operation (the row-at-a-time loop took 1,426
 * instructions a step at n = 38 on such a machine, callgrind: the recorded step twice the plain
 * one). Without either, the same operations a row at a time. */
#include <stdint.h>

/* The terms of one vector of rows j, j+1, ... added into *a, *b, *c (set by the first rows), the
 * same operations in each vector variant: VEC the vector type, MUL, FMADD and ADD its operations,
 * LOAD(k, p) a load from p of the rows whose neighbour j-k exists (k = 0: the rows that exist), 0
 * in the other lanes. */
#define ROW_TERMS(VEC, MUL, FMADD, ADD, LOAD)                                                            \
    do {                                                                                                 \
        VEC dj = LOAD(0, d + j), s = LOAD(0, su + j), uj = LOAD(0, u + j);                               \
        VEC d1 = LOAD(1, d + j - 1), d2 = LOAD(2, d + j - 2), d3 = LOAD(3, d + j - 3);                   \
        VEC k0 = LOAD(0, m + j), k1 = LOAD(1, m + n + j), k2 = LOAD(2, m + 2 * n + j);                   \
        VEC k3 = LOAD(3, m + 3 * n + j);                                                                 \
        VEC t = MUL(k2, d2);                                                                             \
        t = FMADD(k1, d1, t);                                                                            \
        t = FMADD(k3, d3, t);                                                                            \
        t = ADD(t, t);                                                                                   \
        t = FMADD(k0, dj, t);                                                                            \
        if (first) {                                                                                     \
            *a = MUL(uj, s);                                                                             \
            *b = MUL(dj, s);                                                                             \
            *c = MUL(dj, t);                                                                             \
        } else {                                                                                         \
            *a = FMADD(uj, s, *a);                                                                       \
            *b = FMADD(dj, s, *b);                                                                       \
            *c = FMADD(dj, t, *c);                                                                       \
        }                                                                                                \
    } while (0)

#if defined(__AVX512F__)
#include <immintrin.h>

/* Rows j .. j+7 under `mask` (lanes past the last row are 0): added into a, b, c. */
static inline void turn(const double *m, int n, const double *u, const double *d, const double *su, int j,
                        __mmask8 mask, __mmask8 m1, __mmask8 m2, __mmask8 m3, __m512d *a, __m512d *b, __m512d *c,
                        int first)
{
    const __mmask8 lanes[4] = {mask, mask & m1, mask & m2, mask & m3};
#define LOAD(k, p) _mm512_maskz_loadu_pd(lanes[k], (p))
    ROW_TERMS(__m512d, _mm512_mul_pd, _mm512_fmadd_pd, _mm512_add_pd, LOAD);
#undef LOAD
}

/* ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)) in lane 0. */
static inline double lane_sum(__m512d s)
{
    s = _mm512_add_pd(s, _mm512_permute_pd(s, 0x55));
    s = _mm512_add_pd(s, _mm512_permutex_pd(s, 0x4e));
    s = _mm512_add_pd(s, _mm512_shuffle_f64x2(s, s, 0x4e));
    return _mm512_cvtsd_f64(s);
}

void beamstops_energy_rows(int32_t n, const double *m, const double *u, const double *d, const double *su,
                           double *sums)
{
    __m512d a, b, c;
    int j;
    turn(m, n, u, d, su, 0, n >= 8 ? 0xff : (__mmask8)((1u << n) - 1u), 0xfe, 0xfc, 0xf8, &a, &b, &c, 1);
    for (j = 8; j + 8 <= n; j += 8) turn(m, n, u, d, su, j, 0xff, 0xff, 0xff, 0xff, &a, &b, &c, 0);
    if (j < n) turn(m, n, u, d, su, j, (__mmask8)((1u << (n - j)) - 1u), 0xff, 0xff, 0xff, &a, &b, &c, 0);
    sums[0] = lane_sum(a);
    sums[1] = lane_sum(b);
    sums[2] = lane_sum(c);
}

#elif defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>

/* Without AVX-512, with AVX2 and FMA: the same eight partial sums in two 4-lane vectors (rows
 * j .. j+3 of a turn in sums 0..3, rows j+4 .. j+7 in sums 4..7), the same operations lane by
 * lane; loads past either end of the vectors masked to 0 as in the AVX-512 turn. */
static inline __m256d load(const double *p, __m256i mask, int masked)
{
    return masked ? _mm256_maskload_pd(p, mask) : _mm256_loadu_pd(p);
}

/* The lanes of rows j .. j+3 that exist (mask[0]) and whose neighbour j+i-k exists (mask[k]). */
static inline void lane_masks(int n, int j, __m256i mask[4])
{
    const __m256i row = _mm256_add_epi64(_mm256_set1_epi64x(j), _mm256_setr_epi64x(0, 1, 2, 3));
    mask[0] = _mm256_cmpgt_epi64(_mm256_set1_epi64x(n), row);
    for (int k = 1; k <= 3; k++)
        mask[k] = _mm256_and_si256(mask[0], _mm256_cmpgt_epi64(row, _mm256_set1_epi64x(k - 1)));
}

/* Rows j .. j+3 (under `mask` when `masked`): added into a, b, c (set by the first rows). */
static inline void half_turn(const double *m, int n, const double *u, const double *d, const double *su,
                             int j, const __m256i mask[4], int masked, __m256d *a, __m256d *b, __m256d *c,
                             int first)
{
#define LOAD(k, p) load((p), mask[k], masked)
    ROW_TERMS(__m256d, _mm256_mul_pd, _mm256_fmadd_pd, _mm256_add_pd, LOAD);
#undef LOAD
}

/* ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)), s0..s3 in lo and s4..s7 in hi. */
static inline double lane_sum(__m256d lo, __m256d hi)
{
    __m256d pairs = _mm256_hadd_pd(lo, hi); /* s0+s1, s4+s5, s2+s3, s6+s7 */
    __m128d quads = _mm_add_pd(_mm256_castpd256_pd128(pairs), _mm256_extractf128_pd(pairs, 1));
    return _mm_cvtsd_f64(_mm_add_sd(quads, _mm_unpackhi_pd(quads, quads)));
}

void beamstops_energy_rows(int32_t n, const double *m, const double *u, const double *d, const double *su,
                           double *sums)
{
    __m256d a0, a1, b0, b1, c0, c1;
    __m256i mask[4];
    int j;
    lane_masks(n, 0, mask);
    half_turn(m, n, u, d, su, 0, mask, 1, &a0, &b0, &c0, 1);
    lane_masks(n, 4, mask);
    half_turn(m, n, u, d, su, 4, mask, 1, &a1, &b1, &c1, 1);
    for (j = 8; j + 8 <= n; j += 8) {
        half_turn(m, n, u, d, su, j, mask, 0, &a0, &b0, &c0, 0);
        half_turn(m, n, u, d, su, j + 4, mask, 0, &a1, &b1, &c1, 0);
    }
    if (j < n) {
        lane_masks(n, j, mask);
        half_turn(m, n, u, d, su, j, mask, 1, &a0, &b0, &c0, 0);
        lane_masks(n, j + 4, mask);
        half_turn(m, n, u, d, su, j + 4, mask, 1, &a1, &b1, &c1, 0);
    }
    sums[0] = lane_sum(a0, a1);
    sums[1] = lane_sum(b0, b1);
    sums[2] = lane_sum(c0, c1);
}

#else

#if defined(__FMA__)
#define MULADD(x, y, z) __builtin_fma((x), (y), (z))
#else
#define MULADD(x, y, z) ((x) * (y) + (z))
#endif

void beamstops_energy_rows(int32_t n, const double *m, const double *u, const double *d, const double *su,
                           double *sums)
{
    double a[8] = {0}, b[8] = {0}, c[8] = {0}, d1, d2, d3, k1, k2, k3, t;
    int j, l;
    for (j = 0; j < n; j++) {
        l = j % 8;
        d1 = j >= 1 ? d[j - 1] : 0.0;
        d2 = j >= 2 ? d[j - 2] : 0.0;
        d3 = j >= 3 ? d[j - 3] : 0.0;
        k1 = j >= 1 ? m[n + j] : 0.0;
        k2 = j >= 2 ? m[2 * n + j] : 0.0;
        k3 = j >= 3 ? m[3 * n + j] : 0.0;
        t = k2 * d2;
        t = MULADD(k1, d1, t);
        t = MULADD(k3, d3, t);
        t = t + t;
        t = MULADD(m[j], d[j], t);
        if (j < 8) {
            a[l] = u[j] * su[j];
            b[l] = d[j] * su[j];
            c[l] = d[j] * t;
        } else {
            a[l] = MULADD(u[j], su[j], a[l]);
            b[l] = MULADD(d[j], su[j], b[l]);
            c[l] = MULADD(d[j], t, c[l]);
        }
    }
    sums[0] = ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]));
    sums[1] = ((b[0] + b[1]) + (b[2] + b[3])) + ((b[4] + b[5]) + (b[6] + b[7]));
    sums[2] = ((c[0] + c[1]) + (c[2] + c[3])) + ((c[4] + c[5]) + (c[6] + c[7]));
}

#endif
