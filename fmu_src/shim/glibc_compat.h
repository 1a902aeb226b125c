/* Oldest symbol versions for the functions glibc 2.34 moved from libdl into libc.
 *
 * Linked on glibc 2.34 or newer, dlopen and its kin bind to their new version (GLIBC_2.34), and
 * a system with an older glibc cannot load the binary at all: the loader fails before any code
 * of ours runs, so the user gets "version `GLIBC_2.34' not found" instead of our message naming
 * the FMU's floor. Bound to GLIBC_2.2.5 (which every x86-64 glibc exports, since 2.34 as a
 * compatibility version in libc.so.6, before that in libdl.so.2, which the binary then also
 * names: link with -Wl,--no-as-needed -ldl), the FMU's layer and the test host load on any
 * x86-64 glibc. Include before any other header. */
#ifndef SLEWING_GLIBC_COMPAT_H
#define SLEWING_GLIBC_COMPAT_H
#if defined(__x86_64__) && defined(__linux__) && !defined(__ANDROID__)
__asm__(".symver dlopen,dlopen@GLIBC_2.2.5");
__asm__(".symver dlsym,dlsym@GLIBC_2.2.5");
__asm__(".symver dlerror,dlerror@GLIBC_2.2.5");
__asm__(".symver dladdr,dladdr@GLIBC_2.2.5");
__asm__(".symver dlclose,dlclose@GLIBC_2.2.5");
__asm__(".symver dlinfo,dlinfo@GLIBC_2.3.3");
#endif
#endif
