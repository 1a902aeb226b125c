/* Loading the Python that an FMU built with pythonfmu runs its model in.
 *
 * pythonfmu's binary calls the Python C API but is not linked to libpython,
 * and it starts the interpreter without saying where its standard library is.
 * Before that binary is loaded, python_runtime_load() makes a Python visible to
 * it (and to numpy's and the standard library's extension modules): libpython
 * opened with RTLD_GLOBAL, and its home set. Nothing here depends on the FMI
 * version: the FMI 2.0 shim (fmi2_shim.c) calls it, an FMI 3.0 one can too.
 */
#ifndef SLEWING_PYTHON_RUNTIME_H
#define SLEWING_PYTHON_RUNTIME_H

#include <stddef.h>

/* File in the FMU's resources that names the Python the FMU needs (written by build_fmu.py):
 * lines "key=value" with keys version (X.Y.Z), home (prefix) and library (libpython file). */
#define PYTHON_RUNTIME_FILE "python_runtime.txt"
/* Environment variables that override the file on a machine whose Python lives elsewhere. */
#define PYTHON_HOME_VARIABLE "SLEWING_FMU_PYTHONHOME"
#define PYTHON_LIBRARY_VARIABLE "SLEWING_FMU_LIBPYTHON"

/* Directory of the shared library that holds `symbol` (the FMU's binaries/<platform> folder),
 * without a trailing slash. Returns 0, or -1 with a message in err. */
int python_runtime_binary_dir(const void *symbol, char *dir, size_t size, char *err, size_t errsize);

/* Make a Python available to the process, once: nothing when the process already has one
 * (a Python host such as fmpy); otherwise the Python named by the environment variables or
 * by <binary_dir>/../../resources/python_runtime.txt, checked, then started here (without
 * signal handlers, GIL released) so that pythonfmu finds it running and never finalises it.
 * Thread-safe; libpython stays loaded for the life of the process.
 * Returns 0, or -1 with a message for the user in err. */
int python_runtime_load(const char *binary_dir, char *err, size_t errsize);

/* dlopen <binary_dir>/<name> (RTLD_NOW | RTLD_LOCAL) once. At exit (or when this library is
 * unloaded) pythonfmu's hold on the interpreter is released before its static objects are
 * destroyed (release_binary in python_runtime.c: pythonfmu 0.7.0 corrupts the heap at exit
 * otherwise). Returns the handle, or NULL with a message in err. */
void *python_runtime_open_binary(const char *binary_dir, const char *name, char *err, size_t errsize);

/* What both FMI layers do first: Python made available (python_runtime_load), then the binary
 * `name` beside the library that holds `symbol` opened (python_runtime_open_binary). Returns its
 * handle, or NULL with a message in err (also once the binary was released at exit). */
void *python_runtime_start(const void *symbol, const char *name, char *err, size_t errsize);

/* 1 while that binary may be called: not after it was released at exit. */
int python_runtime_binary_open(void);

#ifdef _WIN32
/* Windows: 0 where pythonfmu's DLL can use the resource location, -1 with a message where it holds a
 * character beyond ASCII (raw or percent-encoded): pythonfmu's Windows DLL reads the path both as
 * UTF-8 and in the ANSI code page, and fails or crashes the host with such a folder. */
int python_runtime_check_location(const char *location, char *err, size_t errsize);
#endif

#endif
