/* The writer thread (used by src/beamstops/writer_thread.f90): one thread that carries out one
   write order at a time (beamstops_write_order, src/beamstops/recorder/hdf5_writes.f90), posted
   by the thread of the time loop, which goes on meanwhile. Posting waits until the previous
   order is done, so the orders run one after the other, and `wait` returns once none is
   running (every write an order made is then visible to the caller: the mutex orders them).
   The thread sleeps on a condition variable when it has nothing to do: it takes no CPU time
   of its own. (The job is named here rather than passed as a function pointer: gfortran's
   link-time optimizer loses a bind(c) procedure whose only use is c_funloc.) */
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <float.h>
#include <math.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

/* Copy a record of 8 doubles into the buffer the writer thread reads, with non-temporal stores
   where the buffer is 16-byte aligned (Fortran's allocate: malloc's alignment): the line goes to
   memory without being read first. With ordinary stores, every record wrote into a line the
   writer had read (the buffers go back and forth): the store waited for that line to come back
   from the other CPU, some 7 ns a step on the paper's scene, and several times that when the
   other CPU was busy (the least and median of 10 alternated runs, the store left out: 148 / 172
   against 141 / 145 ns). beamstops_writer_post orders these stores before it hands a buffer over.
   Returns 1 when the 8 values are finite (no NaN, no infinity: beamstops_recorder's all_finite),
   0 otherwise (the row is copied all the same; the recorder then does not count it): one test
   of the vector already loaded, where the Fortran's test was a chain of seven additions. */
int beamstops_stream_row(double *dst, const double *src)
{
#if defined(__AVX512F__) && defined(__AVX512DQ__)
    __m512d v = _mm512_loadu_pd(src);
    /* quiet NaN, +infinity, -infinity, signalling NaN */
    int finite = _mm512_fpclass_pd_mask(v, 0x01 | 0x08 | 0x10 | 0x80) == 0;
    if (((uintptr_t)dst & 63) == 0) {
        _mm512_stream_pd(dst, v);
        return finite;
    }
#elif defined(__AVX__)
    /* |x| <= DBL_MAX, ordered (false for NaN), on two 4-lane vectors */
    const __m256d magnitude = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
    const __m256d largest = _mm256_set1_pd(DBL_MAX);
    __m256d lo = _mm256_and_pd(_mm256_loadu_pd(src), magnitude);
    __m256d hi = _mm256_and_pd(_mm256_loadu_pd(src + 4), magnitude);
    int finite = _mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(lo, largest, _CMP_LE_OQ),
                                                  _mm256_cmp_pd(hi, largest, _CMP_LE_OQ))) == 0xf;
#else
    int finite = 1;
    for (int j = 0; j < 8; j++)
        finite &= fabs(src[j]) <= DBL_MAX;
#endif
#if defined(__SSE2__)
    /* the usual case: malloc's 16 bytes (an ordinary store here made the Figure 4 run's loop
       20 ns a step slower, the line coming back from the writer every time) */
    if (((uintptr_t)dst & 15) == 0) {
        _mm_stream_pd(dst, _mm_loadu_pd(src));
        _mm_stream_pd(dst + 2, _mm_loadu_pd(src + 2));
        _mm_stream_pd(dst + 4, _mm_loadu_pd(src + 4));
        _mm_stream_pd(dst + 6, _mm_loadu_pd(src + 6));
        return finite;
    }
#endif
    memcpy(dst, src, 8 * sizeof(double));
    return finite;
}

/* Carry out the write order at `order` (Fortran, bind(c)). */
void beamstops_write_order(void *order);

typedef struct {
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    void *arg;
    int busy, quit;
    /* The CPUs the process may use, and the one the writer is kept off (-1: none; -2: the
       process's CPUs unknown, the writer's placement left to the kernel). */
    cpu_set_t allowed;
    int excluded;
} writer_t;

static void *writer_main(void *p)
{
    writer_t *w = p;
    pthread_mutex_lock(&w->lock);
    for (;;) {
        while (!w->busy && !w->quit)
            pthread_cond_wait(&w->changed, &w->lock);
        if (!w->busy)
            break;
        pthread_mutex_unlock(&w->lock);
        beamstops_write_order(w->arg);
        pthread_mutex_lock(&w->lock);
        w->busy = 0;
        pthread_cond_broadcast(&w->changed);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

/* The number of CPUs this process may run on (its affinity mask: taskset, a batch system's
   cpuset), at least 1. */
int beamstops_usable_cpus(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) != 0)
        return 1;
    int n = CPU_COUNT(&set);
    return n > 0 ? n : 1;
}

/* A new writer thread, or NULL when none can be started (the orders then run where posted). */
void *beamstops_writer_start(void)
{
    writer_t *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    pthread_mutex_init(&w->lock, NULL);
    pthread_cond_init(&w->changed, NULL);
    w->excluded = -1;
    if (sched_getaffinity(0, sizeof w->allowed, &w->allowed) != 0)
        w->excluded = -2; /* mask unknown: the writer's placement is left to the kernel */
    if (pthread_create(&w->thread, NULL, writer_main, w) != 0) {
        pthread_cond_destroy(&w->changed);
        pthread_mutex_destroy(&w->lock);
        free(w);
        return NULL;
    }
    return w;
}

/* With the lock held: wait until no order runs; 1 when it had to wait. */
static int wait_idle(writer_t *w)
{
    int waited = 0;
    while (w->busy) {
        waited = 1;
        pthread_cond_wait(&w->changed, &w->lock);
    }
    return waited;
}

/* With the lock held and the writer idle: keep it off CPU `cpu` (-1: let it run anywhere the
   process may). The kernel woke the writer on the CPU of the thread that posted the order often
   enough (its wake-up placement takes the waker's CPU when the other looks busy for a moment,
   and the writer then stayed there for tens of orders): the writer's ~0.4 ms an order then
   preempted the time loop while the other CPU was idle. Traced (perf sched:sched_switch, the
   Figure 4 run, 10 runs): in 5 of them the writer ran 4.6-7.8 ms on the loop's CPU, 2-4 ns a step
   of the run's wall. */
static void keep_off(writer_t *w, int cpu)
{
    if (w->excluded == -2 || cpu == w->excluded)
        return;
    cpu_set_t set = w->allowed;
    if (cpu >= 0) {
        if (!CPU_ISSET(cpu, &set))
            return; /* the poster runs outside the process's mask: leave the writer alone */
        CPU_CLR(cpu, &set);
        if (CPU_COUNT(&set) == 0)
            return;
    }
    if (pthread_setaffinity_np(w->thread, sizeof set, &set) == 0)
        w->excluded = cpu;
}

/* Wait until no order runs. */
void beamstops_writer_wait(void *p)
{
    writer_t *w = p;
    if (!w)
        return;
    pthread_mutex_lock(&w->lock);
    wait_idle(w);
    pthread_mutex_unlock(&w->lock);
}

/* Carry out the order at `arg` on the writer thread once the previous one is done (at once,
   here, without a thread). */
void beamstops_writer_post(void *p, void *arg)
{
    writer_t *w = p;
#if defined(__SSE2__)
    _mm_sfence(); /* the records' non-temporal stores (beamstops_stream_row) before the order */
#endif
    if (!w) {
        beamstops_write_order(arg);
        return;
    }
    pthread_mutex_lock(&w->lock);
    /* off the poster's CPU (the time loop's), unless the loop had to wait for the writer: then
       the writer is behind, and may take any CPU the process may use */
    int waited = wait_idle(w);
    keep_off(w, waited ? -1 : sched_getcpu());
    w->arg = arg;
    w->busy = 1;
    pthread_mutex_unlock(&w->lock);
    /* after the unlock: woken with the lock still held, the writer went back to sleep on the
       lock and the unlock had to wake it again (two futex calls a post, strace) */
    pthread_cond_broadcast(&w->changed);
}

/* Finish the last order, end the thread and free it. */
void beamstops_writer_stop(void *p)
{
    writer_t *w = p;
    if (!w)
        return;
    pthread_mutex_lock(&w->lock);
    wait_idle(w);
    w->quit = 1;
    pthread_cond_broadcast(&w->changed);
    pthread_mutex_unlock(&w->lock);
    pthread_join(w->thread, NULL);
    pthread_cond_destroy(&w->changed);
    pthread_mutex_destroy(&w->lock);
    free(w);
}
