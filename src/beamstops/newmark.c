/* The Newmark-weighted sums of a step whose products by beta round (beta other than 0, 1/4 and
 * 1/2), formed once for every loop (beamstops_newmark): the load average, the explicit part of the
 * compliance spring, the work of the load and the discrete energy. Written in Fortran, gfortran
 * fused their products and sums (-march=native, FMA) differently where they were inlined: the
 * one-scene loop and a lockstep group of the program (LTO) then gave one member other bits than the
 * same scene run alone from the step where the sums first rounded apart (beta = 0.3: the work at
 * the 45th step, the tip from the 126th). Here the file is built with -ffp-contract=off
 * (meson.build) and each function is kept out of line, so every caller gets the operations as
 * written, in the order written: the same bits whatever loop, build or inlining calls them. */

#define OUT_OF_LINE __attribute__((noinline, noclone))

/* beta next + (1 - 2 beta) now + beta prev */
OUT_OF_LINE double beamstops_newmark_average(double beta, double next, double now, double prev) {
    return beta * next + (1 - 2 * beta) * now + beta * prev;
}

/* dt2 ((1 - 2 beta) now + beta prev): the explicit part of the Newmark-weighted spring force */
OUT_OF_LINE double beamstops_newmark_explicit(double dt2, double beta, double now, double prev) {
    return dt2 * ((1 - 2 * beta) * now + beta * prev);
}

/* work + 1/2 weight (gd + gd_prev): the work of the load 1/2 G^n.(u^{n+1} - u^{n-1}) added */
OUT_OF_LINE double beamstops_newmark_work(double work, double weight, double gd, double gd_prev) {
    return work + 0.5 * weight * (gd + gd_prev);
}

/* E^{n+1/2} = 1/2 dmd/dt2 + 1/2 (beta usu + beta usu_old + (1 - 2 beta)(usu - dsu)) (SPEC 6) */
OUT_OF_LINE double beamstops_newmark_energy(double dt2, double beta, double dmd, double usu, double dsu,
                                            double usu_old) {
    return 0.5 * dmd / dt2 + 0.5 * (beta * usu + beta * usu_old + (1 - 2 * beta) * (usu - dsu));
}
