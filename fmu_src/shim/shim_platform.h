/* What the FMI layers (fmi2_shim.c, fmi3_shim.c) need of the platform, for Linux and Windows.
 *
 * Linux: glibc's dlsym and pthread mutexes (glibc_compat.h first: the oldest symbol versions).
 * Windows (cross-compiled with mingw-w64, fmu_build/win64.py): GetProcAddress and slim reader/writer
 * locks, so that the DLL needs nothing but KERNEL32 and msvcrt (no winpthread DLL). Include
 * before any other header. */
#ifndef SLEWING_SHIM_PLATFORM_H
#define SLEWING_SHIM_PLATFORM_H

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>

typedef SRWLOCK pthread_mutex_t;
#define PTHREAD_MUTEX_INITIALIZER SRWLOCK_INIT
#define pthread_mutex_lock(m) AcquireSRWLockExclusive(m)
#define pthread_mutex_unlock(m) ReleaseSRWLockExclusive(m)
#define dlsym(handle, name) ((void *)GetProcAddress((HMODULE)(handle), (name)))
#define SHIM_EXPORT __declspec(dllexport)
#define SHIM_INNER_BINARY "pythonfmu-export.dll"
#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

#else
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "glibc_compat.h"
#include <dlfcn.h>
#include <pthread.h>
#define SHIM_EXPORT __attribute__((visibility("default")))
#define SHIM_INNER_BINARY "pythonfmu-export.so"
#endif

#endif
