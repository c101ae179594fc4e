/* sem_clockwait for libfaketime (Debian's 0.9.10 fakes sem_timedwait, not sem_clockwait,
 * which Python 3.11 on glibc >= 2.30 uses for every lock with a timeout: Event.wait,
 * Queue.get, Thread.join would wait in real time for a deadline in accelerated time). The
 * deadline, in the faked clock, becomes a real one: what is left of it divided by the speed
 * of FAKETIME ("+N xSPEED"). Built by obsw_sim.faketime and preloaded before libfaketime. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <semaphore.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

static double speed(void) {
    static double s = 0;
    if (s == 0) {
        const char *f = getenv("FAKETIME");
        const char *x = f ? strchr(f, 'x') : NULL;
        s = x ? atof(x + 1) : 1.0;
        if (s <= 0) s = 1.0;
    }
    return s;
}

int sem_clockwait(sem_t *sem, clockid_t clock, const struct timespec *abstime) {
    static int (*real)(sem_t *, clockid_t, const struct timespec *) = NULL;
    if (!real) real = dlsym(RTLD_NEXT, "sem_clockwait");
    struct timespec now, rnow, abs;
    clock_gettime(clock, &now); /* the faked clock the deadline is in */
    syscall(SYS_clock_gettime, CLOCK_MONOTONIC, &rnow); /* the real one */
    long long ns = (long long)(abstime->tv_sec - now.tv_sec) * 1000000000LL
                 + (abstime->tv_nsec - now.tv_nsec);
    if (ns < 0) ns = 0;
    long long t = (long long)rnow.tv_sec * 1000000000LL + rnow.tv_nsec + (long long)(ns / speed());
    abs.tv_sec = t / 1000000000LL;
    abs.tv_nsec = t % 1000000000LL;
    return real(sem, CLOCK_MONOTONIC, &abs);
}
