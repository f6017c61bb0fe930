/* Whether the BLAS the program runs with is OpenBLAS: openblas_set_num_threads is declared
 * weak, so that it resolves to OpenBLAS's when that library is loaded and stays null with any
 * other BLAS. The program uses it to decide whether to start itself again on one BLAS thread
 * (see one_blas_thread in src/main.f90). */
#include <stddef.h>

extern void openblas_set_num_threads(int) __attribute__((weak));

int beamstops_openblas_loaded(void)
{
    return openblas_set_num_threads != NULL;
}
