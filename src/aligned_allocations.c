/* The program's arrays on cache lines. The engine reads its vectors (u, d, S u, the right-hand
 * side, the diagonals of M and S: 38 values each in the paper's scene) 64 bytes at a time where
 * the machine has AVX-512, and malloc starts a block 16 bytes past a line boundary, or 48: in the
 * program all of u, d, S u, the right-hand side and M's diagonals started 48 bytes past one, so
 * that every such load touched two lines. Linked with -Wl,--wrap=malloc (meson.build), every
 * malloc of the program, of the Python module and of the benchmarks of 256 bytes or more (an
 * array of 32 values) comes here and starts on a line of 64 bytes; free and realloc take such
 * blocks as they take any (glibc). Smaller blocks are HDF5's bookkeeping in the main: aligning
 * those too made a 100-step run 0.1-0.4 ms slower. The engine's loop allocates nothing, so only
 * the start of a run pays. Measured on the Figure 4 run (docs/performance_notes.md, "The
 * engine's arrays on cache lines"): the program's loop and wall about 3 ns a step faster. */
#include <errno.h>
#include <stdlib.h>

void *__real_malloc(size_t size);

/* hidden: the Python module keeps it its own */
__attribute__((visibility("hidden"))) void *__wrap_malloc(size_t size)
{
    enum { line = 64, least = 256 };
    if (size >= least) {
        void *block = NULL;
        if (posix_memalign(&block, line, size) == 0) return block;
        errno = ENOMEM;
        return NULL;
    }
    return __real_malloc(size);
}
