/* The Newmark-weighted sums of a step whose products by beta round (beta other than 0, 1/4 and
 * 1/2), formed once for every loop (beamstops_newmark): the load average, the explicit part of the
 * compliance spring, the work of the load and the discrete energy. Written in Fortran, gfortran
 * fused their products and sums (-march=native, FMA) differently where they were inlined: the
 * one-scene loop and a lockstep group of the program (LTO) then gave one member other bits than the
 * same scene run alone from the step where the sums first rounded apart (beta = 0.3: the work at
 * the 45th step, the tip from the 126th).
 *
 * Here every sum that takes a product is written as the fused multiply-add it is to be (FMA) where
 * the machine has one, so the compiler has nothing left to fuse: inlined into any loop (LTO), vector
 * or scalar, under any -ffp-contract, each function gives the same operations in the same order,
 * and so the same bits. (Kept out of line, as a first version did, the calls cost the one-scene
 * step about 3 ns and lockstep K = 8 and 16 5 to 10 %: the lanes' loops could no longer be vector
 * operations.) Without FMA the products and sums are separate operations everywhere, and gfortran
 * fuses none either. The remaining plain sums (gd + gd_prev, usu - dsu) take no product. The file is
 * built with -ffp-contract=off (meson.build). */

#if defined(__FMA__)
#define FMA(a, b, c) __builtin_fma((a), (b), (c))
#else
#define FMA(a, b, c) ((a) * (b) + (c))
#endif

/* beta next + (1 - 2 beta) now + beta prev: fma(beta, prev, fma(1 - 2 beta, now, beta next)) */
double beamstops_newmark_average(double beta, double next, double now, double prev) {
    return FMA(beta, prev, FMA(1 - 2 * beta, now, beta * next));
}

/* dt2 ((1 - 2 beta) now + beta prev): the explicit part of the Newmark-weighted spring force */
double beamstops_newmark_explicit(double dt2, double beta, double now, double prev) {
    return dt2 * FMA(beta, prev, (1 - 2 * beta) * now);
}

/* work + 1/2 weight (gd + gd_prev): the work of the load 1/2 G^n.(u^{n+1} - u^{n-1}) added */
double beamstops_newmark_work(double work, double weight, double gd, double gd_prev) {
    return FMA(0.5 * weight, gd + gd_prev, work);
}

/* E^{n+1/2} = 1/2 dmd/dt2 + 1/2 (beta usu + beta usu_old + (1 - 2 beta)(usu - dsu)) (SPEC 6) */
double beamstops_newmark_energy(double dt2, double beta, double dmd, double usu, double dsu, double usu_old) {
    double potential = FMA(1 - 2 * beta, usu - dsu, FMA(beta, usu_old, beta * usu));
    return FMA(0.5, potential, 0.5 * dmd / dt2);
}
