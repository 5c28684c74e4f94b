/* blendtool's signal handling (tools/blendtool/signals.c) when the kernel
 * hands the signal to a thread other than the main one. The C++ modules
 * blendtool loads keep worker threads after their call returns (OpenVDB's
 * TBB pool, made while `blendtool vdb` writes), with the signal mask of the
 * time they were made: bt_signals_commit's mask does not cover them. A
 * signal reaching one of them while the output is put in place must not end
 * the run with 128 + N and the output there; one reaching it before must
 * end the run as on the main thread, and a commit that meets a handler
 * already ending the run must not put the output in place. `batch` goes on
 * after each output: there a signal that came during a commit ends the run
 * once the output is in place, and the work after it runs with the signals
 * open.
 *
 * Each case runs in a child process (the handler exits it); the parent
 * checks its exit status and what it left. */
#define _POSIX_C_SOURCE 200809L
#include "blendtool.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char dir[256];
static char temp[300], marker[300], after[300];

static void nap(double s) {
    struct timespec t = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&t, &t) && errno == EINTR) {
    }
}

static int exists(const char *p) {
    struct stat st;
    return lstat(p, &st) == 0;
}

static void touch(const char *p) {
    const int fd = open(p, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd >= 0) close(fd);
}

/* a worker like TBB's: made while the signals are open, sleeping in the
 * kernel when the signal comes (the handler runs on it, then it wakes) */
static void *worker(void *arg) {
    (void)arg;
    struct timespec t = {0, 300000000L};
    nanosleep(&t, NULL); /* ends early when the handler runs here */
    return NULL;
}

/* runs fn in a child; returns its exit status (or 1000 + a killing signal) */
static int in_child(void (*fn)(void)) {
    fflush(NULL);
    const pid_t pid = fork();
    if (pid == 0) {
        fn();
        _exit(0);
    }
    int st = 0;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(st) ? WEXITSTATUS(st) : 1000 + WTERMSIG(st);
}

/* Runs fn in a child (the registered file made first) and checks its exit
 * status and which of the files it left; no case reaches `after`. */
static void expect(void (*fn)(void), int rc, int temp_left, int marker_left) {
    unlink(temp);
    unlink(marker);
    unlink(after);
    touch(temp);
    assert_int_equal(in_child(fn), rc);
    assert_int_equal(exists(temp), temp_left);
    assert_int_equal(exists(marker), marker_left);
    assert_false(exists(after));
}

/* ---- a signal on a worker thread before the commit: the run ends ---- */

static void before_commit(void) {
    bt_signals_install();
    bt_signals_temp(temp);
    pthread_t t;
    pthread_create(&t, NULL, worker, NULL);
    nap(0.05);
    pthread_kill(t, SIGHUP);
    pthread_join(t, NULL);
    nap(2.0); /* the handler exits the process long before */
    touch(marker);
}

static void test_thread_before_commit(void **state) {
    (void)state;
    /* the handler removed the registered file */
    expect(before_commit, 128 + SIGHUP, 0, 0);
}

/* ---- a signal on a worker thread while the output goes in place ---- */

/* SIGTERM on a worker while the output goes in place, as bt_output_commit
 * does it; going_on: as batch, which then opens the signals again and would
 * go on to its next task */
static void commit_with_worker_signal(int going_on) {
    bt_signals_install();
    if (going_on) bt_signals_going_on();
    const int slot = bt_signals_temp(temp);
    pthread_t t;
    pthread_create(&t, NULL, worker, NULL);
    nap(0.05);
    bt_signals_commit();
    pthread_kill(t, SIGTERM);
    pthread_join(t, NULL); /* the handler has run on the worker */
    /* the temporary file is the output now */
    bt_signals_untemp(slot);
    touch(marker);
    bt_signals_reopen();
    if (going_on) touch(after); /* the next task: never reached */
}

static void after_commit(void) {
    commit_with_worker_signal(0);
}

static void test_thread_after_commit(void **state) {
    (void)state;
    /* before signals.c's phase, the handler ran on the worker and exited
     * 143 with the output already there */
    expect(after_commit, 0, 1, 1);
}

/* ---- the same on the main thread: held, and dropped at exit ---- */

static void main_after_commit(void) {
    bt_signals_install();
    bt_signals_temp(temp);
    bt_signals_commit();
    raise(SIGINT);
    nap(0.1);
    touch(marker);
}

static void test_main_after_commit(void **state) {
    (void)state;
    expect(main_after_commit, 0, 1, 1);
}

/* ---- a commit while a worker's handler is ending the run ---- */

/* a child process that says when SIGTERM came (the handler has taken the
 * phase by then: it ends the child first), then takes 0.6 s to end, so the
 * handler is still waiting for it when the main thread reaches the commit */
static int term_came = -1;

static void slow_term(int sig) {
    (void)sig;
    if (write(term_came, "t", 1) != 1) _exit(93);
    struct timespec t = {0, 600000000L};
    nanosleep(&t, NULL);
    _exit(0);
}

static void commit_meets_handler(void) {
    int ready[2], came[2];
    if (pipe(ready) || pipe(came)) _exit(90);
    const pid_t slow = fork();
    if (slow == 0) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = slow_term;
        sigaction(SIGTERM, &sa, NULL);
        close(ready[0]);
        close(came[0]);
        term_came = came[1];
        if (write(ready[1], "x", 1) != 1) _exit(91);
        for (;;) pause();
    }
    char c;
    close(ready[1]);
    close(came[1]);
    if (read(ready[0], &c, 1) != 1) _exit(92);
    bt_signals_install();
    bt_signals_temp(temp);
    bt_signals_child(slow);
    pthread_t t;
    pthread_create(&t, NULL, worker, NULL);
    nap(0.05);
    pthread_kill(t, SIGHUP);
    /* the handler is ending the run (whatever the machine's load) */
    if (read(came[0], &c, 1) != 1) _exit(94);
    bt_signals_commit();
    /* reached only if the commit went on: the output would be put in
     * place while the handler removes it and exits 129 */
    touch(marker);
    _exit(0);
}

static void test_commit_meets_handler(void **state) {
    (void)state;
    expect(commit_meets_handler, 128 + SIGHUP, 0, 0);
}

/* ---- batch: the run goes on after an output, so a signal that came during
 * its commit ends the run once the output is in place ---- */

static void going_on_worker(void) {
    commit_with_worker_signal(1);
}

static void test_going_on_worker(void **state) {
    (void)state;
    /* before bt_signals_reopen, batch held the signals after its first
     * output to the end of the job */
    expect(going_on_worker, 128 + SIGTERM, 1, 1);
}

static void going_on_main(void) {
    bt_signals_install();
    bt_signals_going_on();
    bt_signals_temp(temp);
    bt_signals_commit();
    raise(SIGHUP); /* held on this thread */
    touch(marker);
    bt_signals_reopen();
    touch(after);
}

static void test_going_on_main(void **state) {
    (void)state;
    expect(going_on_main, 128 + SIGHUP, 0, 1);
}

/* going on with no signal: the next output's work runs with the signals
 * open (a signal then ends the run, removing the next temporary file) */
static void going_on_then_signal(void) {
    touch(marker); /* the output before */
    bt_signals_install();
    bt_signals_going_on();
    const int slot = bt_signals_temp(marker);
    bt_signals_commit();
    bt_signals_untemp(slot);
    bt_signals_reopen();
    bt_signals_temp(temp); /* the next output */
    raise(SIGINT);
    touch(after);
}

static void test_going_on_then_signal(void **state) {
    (void)state;
    expect(going_on_then_signal, 128 + SIGINT, 0, 1);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s/lb-signal-threads-XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(dir)) {
        perror(dir);
        return 1;
    }
    snprintf(temp, sizeof temp, "%s/out.lbtmp", dir);
    snprintf(marker, sizeof marker, "%s/went-on", dir);
    snprintf(after, sizeof after, "%s/went-on-after", dir);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_thread_before_commit), cmocka_unit_test(test_thread_after_commit),
        cmocka_unit_test(test_main_after_commit),    cmocka_unit_test(test_commit_meets_handler),
        cmocka_unit_test(test_going_on_worker),      cmocka_unit_test(test_going_on_main),
        cmocka_unit_test(test_going_on_then_signal),
    };
    const int failed = cmocka_run_group_tests(tests, NULL, NULL);
    unlink(temp);
    unlink(marker);
    unlink(after);
    rmdir(dir);
    return failed;
}
