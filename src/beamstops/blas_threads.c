/* One BLAS thread for the program. A threaded OpenBLAS (Debian's libopenblas0-pthread) starts a
 * pool of threads when it loads, and they spin on sched_yield for about 0.1 s of CPU before they
 * sleep, whatever the program does. OpenBLAS's own calls stop it: one thread for what follows,
 * then the pool shut down (as OpenBLAS does itself before a fork); a later LAPACK call on one
 * thread does not start it again. Both functions are declared weak: with another BLAS they are
 * null and nothing is done. */
#include <stddef.h>

extern void openblas_set_num_threads(int) __attribute__((weak));
extern int blas_thread_shutdown_(void) __attribute__((weak));

/* 1 when OpenBLAS's pool was stopped, 0 when the BLAS is not OpenBLAS. */
int beamstops_openblas_one_thread(void)
{
    if (openblas_set_num_threads == NULL || blas_thread_shutdown_ == NULL) return 0;
    openblas_set_num_threads(1);
    blas_thread_shutdown_();
    return 1;
}
