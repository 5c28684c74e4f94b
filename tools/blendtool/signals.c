/* SIGINT, SIGTERM and SIGHUP end every blendtool command at any phase with
 * exit status 128 + the signal (130, 143, 129) and nothing left behind:
 * the handler ends a running child (povray) and waits for it, removes the
 * named temporary files registered here, and exits. Outputs go through
 * lb_output, whose unnamed temporary file vanishes with the process; from
 * bt_signals_commit on the output is being put in place and the signals are
 * held, so an output is either complete or absent. blendtool is a program,
 * not the library: this state is its own.
 *
 * The mask holds the signals for the thread that sets it, not for threads
 * already running: the C++ modules (OpenVDB's TBB workers, OpenImageIO's
 * pool) keep threads after their call returns, with the mask of the time they
 * were made, and the kernel may hand a signal to any of them, also after the
 * commit. So the handler and the commit also agree through one atomic phase:
 * whichever of them moves it first from running wins. A handler that finds
 * the output being put in place returns (the run ends as if the signal had
 * come after it); a commit that finds a handler ending the process waits for
 * that end.
 *
 * A command that writes one output holds the signals from its commit to its
 * exit. `batch` goes on after each output (the next task), so it calls
 * bt_signals_going_on: its commits end with bt_signals_reopen, which opens
 * the signals again and ends the run with a signal that came meanwhile. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <signal.h>
#include <stdatomic.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define MAX_TEMPS 12

/* lock-free, so the handler may use them (C11 7.14.1.1) */
_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "blendtool's signal handler needs lock-free atomics");

enum { RUNNING, COMMITTING, ENDING };
static atomic_int phase = RUNNING;
static atomic_int pending = 0;  /* a signal that came while an output went in place */
static atomic_int going_on = 0; /* more work follows an output (batch) */
static sigset_t before_commit;  /* the main thread's mask before the commit held it */
/* atomics, not volatile: the handler may run on another thread than the one
 * that registers a name, and must see the name before its flag */
static atomic_int child_pid = 0, worker_pid = 0;
static char temps[MAX_TEMPS][4096 + 640];
static atomic_int temp_used[MAX_TEMPS];
static char temp_dir[4096];
static atomic_int temp_dir_used = 0;

static void say(const char *s) {
    ssize_t w = write(STDERR_FILENO, s, strlen(s));
    (void)w;
}

static void on_signal(int sig) {
    int was = RUNNING;
    if (!atomic_compare_exchange_strong(&phase, &was, ENDING)) {
        /* ENDING: another thread's handler is ending the process;
         * COMMITTING: the output goes in place first, then the run ends
         * with it (or, going on, at bt_signals_reopen) */
        if (was == ENDING)
            for (;;) pause();
        atomic_store(&pending, sig);
        return;
    }
    const pid_t pids[2] = {(pid_t)atomic_load(&child_pid), (pid_t)atomic_load(&worker_pid)};
    for (int i = 0; i < 2; ++i)
        if (pids[i] > 0) kill(pids[i], SIGTERM);
    for (int i = 0; i < 2; ++i)
        if (pids[i] > 0) waitpid(pids[i], NULL, 0);
    for (int i = 0; i < MAX_TEMPS; ++i)
        if (atomic_load(&temp_used[i])) unlink(temps[i]);
    if (atomic_load(&temp_dir_used)) rmdir(temp_dir);
    if (atomic_load(&going_on))
        say(sig == SIGINT    ? "\nblendtool: interrupted (SIGINT); the outputs finished before it "
                               "are kept, nothing partial is left\n"
            : sig == SIGTERM ? "blendtool: terminated (SIGTERM); the outputs finished before it "
                               "are kept, nothing partial is left\n"
                             : "blendtool: hung up (SIGHUP); the outputs finished before it are "
                               "kept, nothing partial is left\n");
    else
        say(sig == SIGINT    ? "\nblendtool: interrupted (SIGINT); no output was written\n"
            : sig == SIGTERM ? "blendtool: terminated (SIGTERM); no output was written\n"
                             : "blendtool: hung up (SIGHUP); no output was written\n");
    _exit(128 + sig);
}

/* Hold the three signals; *old (may be NULL) receives the mask before.
 * Registry changes restore that mask afterwards, not an unblocked one: once
 * bt_signals_commit has held the signals for good (the output is being put
 * in place), a registry change must not let a pending signal in, or the
 * handler would exit 128 + signal with the output already there. */
static void hold(sigset_t *old) {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGHUP);
    sigprocmask(SIG_BLOCK, &set, old);
}

static void restore(const sigset_t *old) {
    sigprocmask(SIG_SETMASK, old, NULL);
}

void bt_signals_install(void) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigfillset(&sa.sa_mask); /* one handler at a time */
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (int i = 0; i < 3; ++i) {
        struct sigaction old;
        sigaction(sigs[i], NULL, &old);
        /* a signal the caller ignores (nohup, background jobs) stays ignored */
        if (old.sa_handler != SIG_IGN) sigaction(sigs[i], &sa, NULL);
    }
}

/* The registry is changed with the signals held, so the handler never sees
 * a half-written name. */
int bt_signals_temp(const char *path) {
    if (!path) return -1;
    sigset_t old;
    hold(&old);
    int slot = -1;
    for (int i = 0; i < MAX_TEMPS && slot < 0; ++i)
        if (!atomic_load(&temp_used[i]) && strlen(path) < sizeof temps[i]) slot = i;
    if (slot >= 0) {
        strcpy(temps[slot], path);
        atomic_store(&temp_used[slot], 1);
    }
    restore(&old);
    return slot;
}

void bt_signals_untemp(int slot) {
    if (slot < 0 || slot >= MAX_TEMPS) return;
    sigset_t old;
    hold(&old);
    atomic_store(&temp_used[slot], 0);
    restore(&old);
}

void bt_signals_temp_dir(const char *dir) {
    sigset_t old;
    hold(&old);
    atomic_store(&temp_dir_used, 0);
    if (dir && strlen(dir) < sizeof temp_dir) {
        strcpy(temp_dir, dir);
        atomic_store(&temp_dir_used, 1);
    }
    restore(&old);
}

void bt_signals_child(pid_t pid) {
    atomic_store(&child_pid, (int)pid);
}

void bt_signals_worker(pid_t pid) {
    atomic_store(&worker_pid, (int)pid);
}

void bt_signals_commit(void) {
    sigset_t old;
    hold(&old);
    int was = RUNNING;
    if (atomic_compare_exchange_strong(&phase, &was, COMMITTING))
        before_commit = old;
    else if (was == ENDING)
        for (;;) pause(); /* a handler on another thread removes the output and exits */
}

void bt_signals_going_on(void) {
    atomic_store(&going_on, 1);
}

void bt_signals_reopen(void) {
    int was = COMMITTING;
    if (!atomic_load(&going_on) || !atomic_compare_exchange_strong(&phase, &was, RUNNING)) return;
    const int sig = atomic_exchange(&pending, 0);
    restore(&before_commit); /* one held on this thread arrives here */
    if (sig) raise(sig);     /* one that reached another thread meanwhile */
}
