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
 * its instructions: the README's "The Figure 4 run against its targets"). Without AVX-512, the
 * same operations a row at a time. */
#include <stdint.h>

#if defined(__AVX512F__)
#include <immintrin.h>

/* Rows j .. j+7 under `mask` (lanes past the last row are 0): added into a, b, c. */
static inline void turn(const double *m, int n, const double *u, const double *d, const double *su, int j,
                        __mmask8 mask, __mmask8 m1, __mmask8 m2, __mmask8 m3, __m512d *a, __m512d *b, __m512d *c,
                        int first)
{
    __m512d dj = _mm512_maskz_loadu_pd(mask, d + j);
    __m512d s = _mm512_maskz_loadu_pd(mask, su + j);
    __m512d uj = _mm512_maskz_loadu_pd(mask, u + j);
    __m512d d1 = _mm512_maskz_loadu_pd(mask & m1, d + j - 1);
    __m512d d2 = _mm512_maskz_loadu_pd(mask & m2, d + j - 2);
    __m512d d3 = _mm512_maskz_loadu_pd(mask & m3, d + j - 3);
    __m512d k0 = _mm512_maskz_loadu_pd(mask, m + j);
    __m512d k1 = _mm512_maskz_loadu_pd(mask & m1, m + n + j);
    __m512d k2 = _mm512_maskz_loadu_pd(mask & m2, m + 2 * n + j);
    __m512d k3 = _mm512_maskz_loadu_pd(mask & m3, m + 3 * n + j);
    __m512d t = _mm512_mul_pd(k2, d2);
    t = _mm512_fmadd_pd(k1, d1, t);
    t = _mm512_fmadd_pd(k3, d3, t);
    t = _mm512_add_pd(t, t);
    t = _mm512_fmadd_pd(k0, dj, t);
    if (first) {
        *a = _mm512_mul_pd(uj, s);
        *b = _mm512_mul_pd(dj, s);
        *c = _mm512_mul_pd(dj, t);
    } else {
        *a = _mm512_fmadd_pd(uj, s, *a);
        *b = _mm512_fmadd_pd(dj, s, *b);
        *c = _mm512_fmadd_pd(dj, t, *c);
    }
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
