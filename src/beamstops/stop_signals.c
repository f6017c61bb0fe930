/* A polite stop for `beamstops run` (used by src/beamstops/stop_signals.f90): while the time
 * loop runs, SIGINT and SIGTERM (Ctrl-C, a batch system's time limit, `kill`) only note the
 * signal; the loop looks at the note between two of its blocks and stops there with its records
 * flushed and a checkpoint saved. The note, and the actions it stands in for meanwhile, are the
 * engine's only process-wide mutable state: a signal handler can reach nothing else (it may only
 * set a volatile sig_atomic_t), and the actions are the process's own. A
 * second SIGINT takes the default action (SA_RESETHAND): a user who presses Ctrl-C twice is not
 * kept waiting. A second SIGTERM is noted again: a batch system (or a sweep's worker, and the
 * signal sent to the whole group) may send it twice, and forces the end with SIGKILL after its
 * grace period. SA_RESTART: the writer thread's writes, if the signal lands on it, go on. */
#include <signal.h>
#include <string.h>

static volatile sig_atomic_t caught = 0;
static struct sigaction previous_int, previous_term;
static int catching = 0;

static void note(int signum) { caught = signum; }

/* Note SIGINT and SIGTERM from now on (instead of their action; those ignored stay ignored). */
void beamstops_catch_stop_signals(void)
{
    struct sigaction interrupt, terminate;
    if (catching) return;
    memset(&interrupt, 0, sizeof interrupt);
    interrupt.sa_handler = note;
    sigemptyset(&interrupt.sa_mask);
    terminate = interrupt;
    interrupt.sa_flags = SA_RESETHAND | SA_RESTART;
    terminate.sa_flags = SA_RESTART;
    caught = 0;
    /* a signal the process ignores (the SIGINT of a job a script put in the background) stays ignored */
    sigaction(SIGINT, NULL, &previous_int);
    sigaction(SIGTERM, NULL, &previous_term);
    if (previous_int.sa_handler != SIG_IGN) sigaction(SIGINT, &interrupt, NULL);
    if (previous_term.sa_handler != SIG_IGN) sigaction(SIGTERM, &terminate, NULL);
    catching = 1;
}

/* The actions SIGINT and SIGTERM had before beamstops_catch_stop_signals. */
void beamstops_release_stop_signals(void)
{
    if (!catching) return;
    sigaction(SIGINT, &previous_int, NULL);
    sigaction(SIGTERM, &previous_term, NULL);
    catching = 0;
}

/* The signal noted since beamstops_catch_stop_signals, while the signals are caught (0: none,
   or not catching: a loop after beamstops_release_stop_signals, an ensemble's members, goes on). */
int beamstops_stop_signal(void) { return catching ? caught : 0; }

/* The signal noted the last time the signals were caught (0: none), for the run's report. */
int beamstops_caught_signal(void) { return caught; }

/* The name of a signal the loop stops on ("SIGINT", "SIGTERM"; "signal" otherwise). */
const char *beamstops_stop_signal_name(int signum)
{
    return signum == SIGINT ? "SIGINT" : signum == SIGTERM ? "SIGTERM" : "signal";
}
