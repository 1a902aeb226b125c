/* Forced into every C file of the CPython that tests/linux_floor/build.sh compiles in Debian 11 (glibc 2.31), so
 * that it needs nothing newer than glibc 2.28 (RHEL 8, Debian 10).
 *
 * glibc 2.29 gave exp, exp2, log, log2 and pow new symbol versions (the same functions without the old SVID error
 * wrapper); the versions of 2.2.5 are still exported by every x86-64 glibc. Bound to them, libpython, math,
 * cmath and _statistics load on glibc 2.28. Both set errno alike in POSIX mode, which is what CPython checks.
 * (sem_clockwait, glibc 2.30, is switched off at configure time instead: ac_cv_func_sem_clockwait=no.) */
#if defined(__x86_64__) && defined(__linux__)
__asm__(".symver exp,exp@GLIBC_2.2.5");
__asm__(".symver exp2,exp2@GLIBC_2.2.5");
__asm__(".symver log,log@GLIBC_2.2.5");
__asm__(".symver log2,log2@GLIBC_2.2.5");
__asm__(".symver pow,pow@GLIBC_2.2.5");
#endif
