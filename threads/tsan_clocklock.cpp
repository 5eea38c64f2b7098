// Built into every executable of a ThreadSanitizer build only (ROBODAMP_SANITIZE=thread; docs/tests.md,
// "Sanitizers"). GCC 12's ThreadSanitizer intercepts pthread_mutex_lock and pthread_mutex_timedlock but not
// glibc 2.34's pthread_mutex_clocklock, which libstdc++'s timed mutexes use with the steady clock, and so
// Debian's Fast DDS for every one of its locks. TSan then sees the unlock without the lock: it reports
// "unlock of an unlocked mutex", and, having no order between Fast DDS's threads, races inside Fast DDS
// that its locks prevent. This definition, found before libc's (the executable comes first), tells TSan
// of the lock through its public annotations and takes it with libc's function: the locks are seen and
// ordered, so nothing about Fast DDS needs suppressing for them.
#include <dlfcn.h>
#include <pthread.h>
#include <sanitizer/tsan_interface.h>

#include <ctime>

extern "C" int pthread_mutex_clocklock(pthread_mutex_t* mutex, clockid_t clock, const struct timespec* abstime) {
  using Lock = int (*)(pthread_mutex_t*, clockid_t, const struct timespec*);
  static const Lock libc_lock = reinterpret_cast<Lock>(dlsym(RTLD_NEXT, "pthread_mutex_clocklock"));
  __tsan_mutex_pre_lock(mutex, __tsan_mutex_try_lock);
  const int rc = libc_lock(mutex, clock, abstime);
  __tsan_mutex_post_lock(mutex, rc == 0 ? __tsan_mutex_try_lock : __tsan_mutex_try_lock | __tsan_mutex_try_lock_failed,
                         0);
  return rc;
}
