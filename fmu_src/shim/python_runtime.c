/* Loading the Python that an FMU built with pythonfmu runs its model in (see python_runtime.h). */
#define _GNU_SOURCE
#include "glibc_compat.h"
#include "python_runtime.h"

#include <gnu/libc-version.h>

#include <dirent.h>
#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <wchar.h>

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static int python_ready = 0;

static void message(char *err, size_t size, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(err, size, format, args);
    va_end(args);
}

int python_runtime_binary_dir(const void *symbol, char *dir, size_t size, char *err, size_t errsize)
{
    Dl_info info;
    char resolved[PATH_MAX];
    if (!dladdr(symbol, &info) || !info.dli_fname || !realpath(info.dli_fname, resolved)) {
        message(err, errsize, "the FMU cannot find its own binary (dladdr)");
        return -1;
    }
    char *slash = strrchr(resolved, '/');
    if (!slash || (size_t)(slash - resolved) >= size) {
        message(err, errsize, "the FMU's binary path is too long: %s", resolved);
        return -1;
    }
    *slash = '\0';
    snprintf(dir, size, "%s", resolved);
    return 0;
}

struct runtime_file {
    char runtime[32];   /* "standalone": the FMU carries its Python (folder); else the host's Python (home...) */
    char folder[PATH_MAX];  /* standalone: the runtime's prefix, relative to the binary's folder */
    char glibc[32];     /* the oldest glibc the FMU's binaries load with (X.Y) */
    char glibcxx[32];   /* the newest libstdc++ symbol version they need (3.4.N), or "" */
    char packages[256]; /* what the runtime carries, for messages */
    char version[64];   /* X.Y.Z of the building Python */
    char home[PATH_MAX];
    char library[PATH_MAX + 64];
    char environment[PATH_MAX];  /* the prefix with the packages: a virtual environment, or the home */
    char path[PATH_MAX];
    int found;
};

static void read_runtime_file(const char *binary_dir, struct runtime_file *rt)
{
    memset(rt, 0, sizeof *rt);
    snprintf(rt->path, sizeof rt->path, "%s/../../resources/%s", binary_dir, PYTHON_RUNTIME_FILE);
    FILE *fh = fopen(rt->path, "r");
    if (!fh)
        return;
    rt->found = 1;
    char line[PATH_MAX + 64];
    while (fgets(line, sizeof line, fh)) {
        line[strcspn(line, "\r\n")] = '\0';
        char *eq = strchr(line, '=');
        if (line[0] == '#' || !eq)
            continue;
        *eq = '\0';
        const char *value = eq + 1;
        if (!strcmp(line, "runtime"))
            snprintf(rt->runtime, sizeof rt->runtime, "%s", value);
        else if (!strcmp(line, "folder"))
            snprintf(rt->folder, sizeof rt->folder, "%s", value);
        else if (!strcmp(line, "glibc"))
            snprintf(rt->glibc, sizeof rt->glibc, "%s", value);
        else if (!strcmp(line, "glibcxx"))
            snprintf(rt->glibcxx, sizeof rt->glibcxx, "%s", value);
        else if (!strcmp(line, "packages"))
            snprintf(rt->packages, sizeof rt->packages, "%s", value);
        else if (!strcmp(line, "version"))
            snprintf(rt->version, sizeof rt->version, "%s", value);
        else if (!strcmp(line, "home"))
            snprintf(rt->home, sizeof rt->home, "%s", value);
        else if (!strcmp(line, "library"))
            snprintf(rt->library, sizeof rt->library, "%s", value);
        else if (!strcmp(line, "environment"))
            snprintf(rt->environment, sizeof rt->environment, "%s", value);
    }
    fclose(fh);
}

/* "3.11" from "3.11.7" or from "libpython3.11.so.1.0"; 0 if none */
static int minor_version(const char *text, char *out, size_t size)
{
    const char *p = strstr(text, "python");
    p = p ? p + 6 : text;
    int major, minor;
    if (sscanf(p, "%d.%d", &major, &minor) != 2)
        return 0;
    snprintf(out, size, "%d.%d", major, minor);
    return 1;
}

static int exists(const char *path)
{
    return access(path, R_OK) == 0;
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* The standard advice, appended to every failure: what to install and what to set. */
static void advice(char *err, size_t size, const char *minor)
{
    size_t used = strlen(err);
    message(err + used, size - used,
            " This FMU runs its model in CPython %s with numpy, in the host's process: install that "
            "CPython with its shared library (libpython%s.so.1.0) and numpy, then set %s to its prefix "
            "(for example /usr) or to a virtual environment made from it, and %s to its libpython if that is not <prefix>/lib/ "
            "nor on the system's library path.",
            minor, minor, PYTHON_HOME_VARIABLE, PYTHON_LIBRARY_VARIABLE);
}

/* The Python home of `prefix`: the prefix itself, or for a virtual environment (pyvenv.cfg)
 * the installation it was made from. */
static void resolve_home(const char *prefix, char *home, size_t size)
{
    snprintf(home, size, "%s", prefix);
    char cfg[PATH_MAX + 16];
    snprintf(cfg, sizeof cfg, "%s/pyvenv.cfg", prefix);
    FILE *fh = fopen(cfg, "r");
    if (!fh)
        return;
    char line[PATH_MAX + 64];
    while (fgets(line, sizeof line, fh)) {
        line[strcspn(line, "\r\n")] = '\0';
        char *eq = strchr(line, '=');
        if (!eq)
            continue;
        char *key = line, *value = eq + 1;
        *eq = '\0';
        while (*key == ' ')
            key++;
        for (char *end = eq - 1; end >= key && *end == ' '; end--)
            *end = '\0';
        while (*value == ' ')
            value++;
        if (strcmp(key, "home"))
            continue;
        size_t n = strlen(value);  /* home = <installation>/bin */
        if (n >= 4 && !strcmp(value + n - 4, "/bin"))
            value[n - 4] = '\0';
        snprintf(home, size, "%s", value);
        break;
    }
    fclose(fh);
}

/* -1, 0 or 1 as version a is older than, equal to or newer than b ("2.31" against "2.35") */
static int compare_versions(const char *a, const char *b)
{
    while (*a || *b) {
        long x = strtol(a, (char **)&a, 10), y = strtol(b, (char **)&b, 10);
        if (x != y)
            return x < y ? -1 : 1;
        if (*a == '.')
            a++;
        if (*b == '.')
            b++;
        if (!*a && !*b)
            break;
    }
    return 0;
}

/* Systems that qualify for a glibc floor, for the messages: the oldest release of each family at or above it. */
static void systems_for(const char *glibc, char *out, size_t size)
{
    static const struct { const char *glibc, *family, *name; } systems[] = {
        {"2.28", "D", "Debian 10"}, {"2.28", "R", "RHEL 8"}, {"2.31", "D", "Debian 11"}, {"2.31", "U", "Ubuntu 20.04"},
        {"2.34", "R", "RHEL 9"}, {"2.35", "U", "Ubuntu 22.04"}, {"2.36", "D", "Debian 12"}, {"2.39", "U", "Ubuntu 24.04"},
        {"2.39", "R", "RHEL 10"}, {"2.41", "D", "Debian 13"}};
    char seen[8] = "";
    size_t n = 0;
    out[0] = '\0';
    for (size_t i = 0; i < sizeof systems / sizeof systems[0]; i++)
        if (compare_versions(systems[i].glibc, glibc) >= 0 && !strstr(seen, systems[i].family) && n < size) {
            n += snprintf(out + n, size - n, "%s%s", *seen ? ", " : "", systems[i].name);
            strcat(seen, systems[i].family);
        }
}

/* The GCC whose libstdc++ first has GLIBCXX_<glibcxx> ("3.4.28": 10), for the messages; 0 if unknown. */
static int gcc_for(const char *glibcxx)
{
    int major = 0, minor = 0, patch = 0;
    if (sscanf(glibcxx, "%d.%d.%d", &major, &minor, &patch) != 3 || major != 3 || minor != 4)
        return 0;
    static const int gcc[] = {5, 6, 7, 7, 8, 9, 9, 10};     /* GLIBCXX_3.4.21 .. 3.4.28 */
    return patch >= 29 ? patch - 18 : patch >= 21 ? gcc[patch - 21] : 0;
}

/* What the machine needs, for the messages: "Linux x86-64, for example Debian 11, Ubuntu 20.04, RHEL 9 or
 * newer, with libstdc++ of GCC 10 or newer, as they have". */
static void requirement(const struct runtime_file *rt, char *out, size_t size)
{
    char systems[128];
    int gcc = gcc_for(rt->glibcxx);
    systems_for(rt->glibc, systems, sizeof systems);
    int n = snprintf(out, size, "Linux x86-64%s%s%s", *systems ? ", for example " : "", systems,
                     *systems ? " or newer" : "");
    if (gcc && n >= 0 && (size_t)n < size)
        snprintf(out + n, size - n, ", with libstdc++ of GCC %d or newer%s", gcc, *systems ? ", as they have" : "");
}

/* The FMU's binaries need glibc rt->glibc or newer: refuse an older system with a message that
 * names the floor, before anything that needs it is loaded (the loader's own message would be a
 * bare "version `GLIBC_2.35' not found" from inside the host). 0, or -1 with a message. */
static int check_glibc(const struct runtime_file *rt, char *err, size_t errsize)
{
    const char *have = gnu_get_libc_version();
    if (!*rt->glibc || compare_versions(have, rt->glibc) >= 0)
        return 0;
    char needs[256];
    requirement(rt, needs, sizeof needs);
    message(err, errsize,
            "this FMU needs glibc %s or newer (%s); "
            "this machine has glibc %s. Run it on a newer system, or ask for an FMU built on a system whose "
            "glibc is at most %s (build_fmu.py states the floor of each FMU it builds).",
            rt->glibc, needs, have, have);
    return -1;
}

/* Set one of Python's legacy configuration flags (Py_IgnoreEnvironmentFlag...) before it starts. */
static void set_flag(void *handle, const char *name, int value)
{
    int *flag = (int *)dlsym(handle, name);
    if (flag)
        *flag = value;
}

/* Python code that appends the runtime's folders to sys.path where they are missing: the
 * standard library, its extension modules and site-packages (<home>/lib/pythonX.Y/...). Returns
 * 0, or -1 where the path cannot be written into a Python string literal. */
static int append_runtime_paths(const char *home, const char *minor, char *code, size_t size)
{
    if (strpbrk(home, "'\\\n"))
        return -1;
    snprintf(code, size,
             "import sys\n"
             "for p in ('%s/lib/python%s', '%s/lib/python%s/lib-dynload', '%s/lib/python%s/site-packages'):\n"
             "    if p not in sys.path: sys.path.append(p)\n", home, minor, home, minor, home, minor);
    return 0;
}

/* Load the libraries the runtime carries beside libpython (<home>/lib: libffi, libexpat...) by
 * their path, before libpython and the extension modules that need them: those without a
 * RUNPATH (a distribution's Python) find them then by their name among the loaded objects. A
 * library the process already holds under that name is left as it is. Libraries that need
 * another bundled one are retried until no more loads. */
static void preload_libraries(const char *home)
{
    char folder[PATH_MAX + 8], path[2 * PATH_MAX];
    snprintf(folder, sizeof folder, "%s/lib", home);
    for (int progress = 1; progress;) {
        progress = 0;
        DIR *dir = opendir(folder);
        if (!dir)
            return;
        struct dirent *entry;
        while ((entry = readdir(dir)) != NULL) {
            const char *name = entry->d_name;
            if (strncmp(name, "lib", 3) || !strstr(name, ".so") || !strncmp(name, "libpython", 9))
                continue;
            if (dlopen(name, RTLD_NOW | RTLD_NOLOAD))
                continue;  /* loaded already: by us, or by the host under that name */
            snprintf(path, sizeof path, "%s/%s", folder, name);
            if (dlopen(path, RTLD_NOW | RTLD_NOLOAD))
                continue;  /* loaded by us from this file, whose name is not its soname (libgomp.so.1.0.0) */
            if (dlopen(path, RTLD_NOW | RTLD_GLOBAL))
                progress = 1;
        }
        closedir(dir);
    }
}

/* The Python the FMU carries (runtime=standalone): <binary_dir>/<folder>, a Python prefix with
 * the standard library, numpy and, where built so, numba. Started isolated: the host's
 * environment (PYTHONPATH, PYTHONHOME) and user site-packages are not looked at, so the model
 * runs with exactly the packages it was built with. */
static int load_standalone(const char *binary_dir, const struct runtime_file *rt, char *err, size_t errsize)
{
    char home[PATH_MAX], library[PATH_MAX + 64], stdlib[PATH_MAX + 64], program[PATH_MAX + 32];
    char minor[16] = "3";
    if (!minor_version(rt->version, minor, sizeof minor)) {
        message(err, errsize, "resources/%s names no Python version.", PYTHON_RUNTIME_FILE);
        return -1;
    }
    snprintf(home, sizeof home, "%s/%s", binary_dir, rt->folder);
    snprintf(library, sizeof library, "%s/lib/%s", home, rt->library);
    snprintf(stdlib, sizeof stdlib, "%s/lib/python%s/encodings/__init__.py", home, minor);
    if (!exists(library) || !exists(stdlib)) {
        message(err, errsize, "the FMU's Python runtime is incomplete: %s is missing (was the FMU unpacked whole?).",
                exists(library) ? stdlib : library);
        return -1;
    }
    preload_libraries(home);
    void *handle = dlopen(library, RTLD_NOW | RTLD_GLOBAL);
    if (!handle) {
        char needs[256];
        requirement(rt, needs, sizeof needs);
        message(err, errsize, "cannot load the FMU's Python library %s: %s (the FMU needs glibc %s or newer: %s).",
                library, dlerror(), rt->glibc, needs);
        return -1;
    }
    void (*set_home)(const wchar_t *) = (void (*)(const wchar_t *))dlsym(handle, "Py_SetPythonHome");
    void (*set_program)(const wchar_t *) = (void (*)(const wchar_t *))dlsym(handle, "Py_SetProgramName");
    wchar_t *(*decode)(const char *, size_t *) = (wchar_t * (*)(const char *, size_t *)) dlsym(handle, "Py_DecodeLocale");
    void (*initialize)(int) = (void (*)(int))dlsym(handle, "Py_InitializeEx");
    void *(*save_thread)(void) = (void *(*)(void))dlsym(handle, "PyEval_SaveThread");
    if (!set_home || !decode || !initialize || !save_thread) {
        message(err, errsize, "%s lacks Py_SetPythonHome, Py_DecodeLocale, Py_InitializeEx or PyEval_SaveThread.",
                library);
        return -1;
    }
    set_flag(handle, "Py_IgnoreEnvironmentFlag", 1);   /* no PYTHONPATH, PYTHONHOME... of the host */
    set_flag(handle, "Py_NoUserSiteDirectory", 1);     /* no ~/.local/lib/pythonX.Y/site-packages */
    set_flag(handle, "Py_UTF8Mode", 1);                /* an FMU folder with non-ASCII names in a C locale */
    set_home(decode(home, NULL));                      /* Python copies it (the copy of 400 bytes is kept) */
    snprintf(program, sizeof program, "%s/bin/python%s", home, minor);
    if (set_program)
        set_program(decode(program, NULL));            /* sys.executable: none of the host's Pythons */
    initialize(0);                                     /* no signal handlers: the host keeps Ctrl-C */
    /* site-packages named whatever the building Python's site module adds (Debian's: dist-packages) */
    int (*run)(const char *, void *) = (int (*)(const char *, void *))dlsym(handle, "PyRun_SimpleStringFlags");
    char code[4 * PATH_MAX + 256];
    if (run && append_runtime_paths(home, minor, code, sizeof code) == 0)
        run(code, NULL);
    save_thread();                                     /* the GIL released for pythonfmu's PyGILState calls */
    return 0;
}

/* In a process whose Python was started by someone else (a Python host, or another FMU of ours
 * that carries other packages, such as a drive FMU without numba beside a bearing FMU with it):
 * where that Python is of the version this FMU carries, append this FMU's standard library and
 * site-packages to sys.path. Modules already imported (numpy) stay the first ones; what the
 * process lacks (numba, numpy in a Python host without it, or a standard-library module whose
 * first FMU's folder the host has deleted) comes from this FMU. Appended, never put first: the
 * host's own packages win. */
static void offer_packages(const char *binary_dir, const struct runtime_file *rt)
{
    const char *(*get_version)(void) = (const char *(*)(void))dlsym(RTLD_DEFAULT, "Py_GetVersion");
    int (*ensure)(void) = (int (*)(void))dlsym(RTLD_DEFAULT, "PyGILState_Ensure");
    void (*release)(int) = (void (*)(int))dlsym(RTLD_DEFAULT, "PyGILState_Release");
    int (*run)(const char *, void *) = (int (*)(const char *, void *))dlsym(RTLD_DEFAULT, "PyRun_SimpleStringFlags");
    char running[16], carried[16], home[PATH_MAX], code[4 * PATH_MAX + 256];
    snprintf(home, sizeof home, "%s/%s", binary_dir, rt->folder);
    if (!get_version || !ensure || !release || !run || !minor_version(get_version(), running, sizeof running)
        || !minor_version(rt->version, carried, sizeof carried) || strcmp(running, carried)
        || append_runtime_paths(home, carried, code, sizeof code) != 0)
        return;
    int state = ensure();
    run(code, NULL);
    release(state);
}

static int load_locked(const char *binary_dir, char *err, size_t errsize)
{
    if (python_ready)
        return 0;
    struct runtime_file rt;
    read_runtime_file(binary_dir, &rt);
    if (check_glibc(&rt, err, errsize) != 0)
        return -1;
    int (*is_initialized)(void) = (int (*)(void))dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    if (is_initialized && !is_initialized()) {
        /* a host linked to libpython that has not started it: a second libpython cannot be loaded
         * beside it, and starting the host's own is the host's business */
        message(err, errsize, "this process holds a Python library (%s) that is not started: the FMU cannot start "
                "its own Python beside it. Start Python in the host first (Py_Initialize), or run the FMU in a host "
                "that is not linked to libpython.", "libpython");
        return -1;
    }
    if (is_initialized) {
        /* a Python host (fmpy...), a host linked to libpython, or another FMU of ours that
         * started its Python in this process: one process holds one CPython, so use it */
        if (!strcmp(rt.runtime, "standalone"))
            offer_packages(binary_dir, &rt);
        python_ready = 1;
        return 0;
    }
    if (!strcmp(rt.runtime, "standalone")) {
        if (load_standalone(binary_dir, &rt, err, errsize) != 0)
            return -1;
        python_ready = 1;
        return 0;
    }
    const char *env_home = getenv(PYTHON_HOME_VARIABLE);
    const char *env_library = getenv(PYTHON_LIBRARY_VARIABLE);
    if (env_home && !*env_home)
        env_home = NULL;
    if (env_library && !*env_library)
        env_library = NULL;
    char built_minor[16] = "3";
    if (!minor_version(rt.version, built_minor, sizeof built_minor))
        snprintf(built_minor, sizeof built_minor, "3.11");

    if (!env_home && !rt.found) {
        message(err, errsize, "%s is missing and %s is not set.", rt.path, PYTHON_HOME_VARIABLE);
        advice(err, errsize, built_minor);
        return -1;
    }
    char home_buffer[PATH_MAX];
    if (env_home)
        resolve_home(env_home, home_buffer, sizeof home_buffer);
    const char *home = env_home ? home_buffer : rt.home;
    const char *origin = env_home ? "set by " PYTHON_HOME_VARIABLE : "named in resources/" PYTHON_RUNTIME_FILE;

    /* the library: explicit, under the home, or the system's one of the building minor version */
    char library[PATH_MAX + 64];
    if (env_library) {
        snprintf(library, sizeof library, "%s", env_library);
    } else if (env_home) {
        snprintf(library, sizeof library, "%s/lib/libpython%s.so.1.0", home, built_minor);
        if (!exists(library))
            snprintf(library, sizeof library, "%s/lib/libpython%s.so", home, built_minor);
        if (!exists(library))  /* e.g. Debian's /usr/lib/x86_64-linux-gnu, through the loader's search */
            snprintf(library, sizeof library, "libpython%s.so.1.0", built_minor);
    } else {
        snprintf(library, sizeof library, "%s", rt.library);
    }
    if (strchr(library, '/') && !exists(library)) {
        message(err, errsize, "the Python library %s (%s) does not exist on this machine.", library,
                env_library ? "set by " PYTHON_LIBRARY_VARIABLE : origin);
        advice(err, errsize, built_minor);
        return -1;
    }

    /* check the home before the library is loaded: a wrong home aborts the process in Py_Initialize */
    char minor[16];
    if (!minor_version(base_name(library), minor, sizeof minor))
        snprintf(minor, sizeof minor, "%s", built_minor);
    char stdlib[PATH_MAX + 64];
    snprintf(stdlib, sizeof stdlib, "%s/lib/python%s/encodings/__init__.py", home, minor);
    if (!exists(stdlib)) {
        message(err, errsize, "the Python home %s (%s) holds no standard library of Python %s (%s is missing).",
                home, origin, minor, stdlib);
        advice(err, errsize, built_minor);
        return -1;
    }

    void *handle = dlopen(library, RTLD_NOW | RTLD_GLOBAL);
    if (!handle) {
        message(err, errsize, "cannot load the Python library %s: %s.", library, dlerror());
        advice(err, errsize, built_minor);
        return -1;
    }
    const char *(*get_version)(void) = (const char *(*)(void))dlsym(handle, "Py_GetVersion");
    char loaded[16] = "?";
    if (!get_version || !minor_version(get_version(), loaded, sizeof loaded) || strcmp(loaded, minor)) {
        dlclose(handle);  /* nothing has bound to it yet */
        message(err, errsize, "%s is Python %s, but the home %s is Python %s.", library, loaded, home, minor);
        advice(err, errsize, built_minor);
        return -1;
    }
    /* the home: through the API where it exists (no change to the host's environment) */
    void (*set_home)(const wchar_t *) = (void (*)(const wchar_t *))dlsym(handle, "Py_SetPythonHome");
    wchar_t *(*decode)(const char *, size_t *) = (wchar_t * (*)(const char *, size_t *)) dlsym(handle, "Py_DecodeLocale");
    wchar_t *whome = decode ? decode(home, NULL) : NULL;
    if (set_home && whome)
        set_home(whome);  /* kept: Python keeps the pointer */
    else
        setenv("PYTHONHOME", home, 1);
    void (*set_program)(const wchar_t *) = (void (*)(const wchar_t *))dlsym(handle, "Py_SetProgramName");
    char program[PATH_MAX + 64];
    snprintf(program, sizeof program, "%s/bin/python%s", home, minor);
    wchar_t *wprogram = decode && exists(program) ? decode(program, NULL) : NULL;
    if (set_program && wprogram)
        set_program(wprogram);  /* sys.executable: the Python named, not the first on PATH */
    /* Start Python here, once, without its signal handlers (the host keeps Ctrl-C), and release
     * the GIL for pythonfmu's PyGILState calls. pythonfmu then finds it started and never
     * finalises it: numpy cannot be imported again after a finalisation. */
    void (*initialize)(int) = (void (*)(int))dlsym(handle, "Py_InitializeEx");
    void *(*save_thread)(void) = (void *(*)(void))dlsym(handle, "PyEval_SaveThread");
    if (!initialize || !save_thread) {
        message(err, errsize, "%s lacks Py_InitializeEx or PyEval_SaveThread.", library);
        return -1;
    }
    initialize(0);
    /* a virtual environment's packages (numpy...): what its own python3 would add at start-up */
    const char *environment = env_home ? env_home : rt.environment;
    char cfg[PATH_MAX + 16], code[2 * PATH_MAX + 128];
    snprintf(cfg, sizeof cfg, "%s/pyvenv.cfg", environment);
    int (*run)(const char *, void *) = (int (*)(const char *, void *))dlsym(handle, "PyRun_SimpleStringFlags");
    if (*environment && exists(cfg) && run && !strpbrk(environment, "'\\\n")) {
        /* as the environment's own python3 does: its site-packages instead of the base's (which
         * site.addsitedir alone would leave first, so the base's numpy would win over the venv's) */
        snprintf(code, sizeof code,
                 "import site, sys\n"
                 "base = set(site.getsitepackages())\n"
                 "sys.path[:] = [p for p in sys.path if p not in base]\n"
                 "site.addsitedir('%s/lib/python%s/site-packages')\n", environment, minor);
        run(code, NULL);
    }
    save_thread();
    python_ready = 1;  /* libpython stays loaded: the handle is never closed */
    return 0;
}

int python_runtime_load(const char *binary_dir, char *err, size_t errsize)
{
    pthread_mutex_lock(&lock);
    int status = load_locked(binary_dir, err, errsize);
    pthread_mutex_unlock(&lock);
    return status;
}

static void *binary_handle = NULL;

/* At the process's exit (or when the host unloads this library), release pythonfmu's hold on
 * the interpreter before the C runtime destroys pythonfmu's static objects.
 *
 * pythonfmu 0.7.0 keeps its interpreter holder in a static std::shared_ptr. Its binary holds
 * STB_GNU_UNIQUE symbols, so dlclose never unloads it: it is always torn down at exit, where
 * glibc runs the static destructors (exit's handlers) before the ELF destructors (_dl_fini).
 * The shared_ptr is destroyed first, freeing its block when no instance is left, and then
 * pythonfmu's ELF destructor, finalizePythonInterpreter(), assigns nullptr to that destroyed
 * object: it decrements a count inside the freed block, which corrupts the heap ("free():
 * corrupted unsorted chunks", "corrupted double-linked list"; valgrind: invalid read in
 * finalizePythonInterpreter of a block freed by __run_exit_handlers). Whether the process
 * then aborts depends on the heap's layout: seen as a sporadic abort at the end of a run.
 *
 * Registered after pythonfmu's binary was loaded, this handler runs before its static
 * destructors: it calls finalizePythonInterpreter() while the holder is alive, which empties
 * it; the static destructor and the ELF destructor then find it empty and do nothing.
 * Python is not finalised (we started it, or the host did), so this is safe to run early. */
static void release_binary(void)
{
    pthread_mutex_lock(&lock);
    if (binary_handle) {
        void (*finalize)(void) = (void (*)(void))dlsym(binary_handle, "finalizePythonInterpreter");
        if (finalize)
            finalize();
    }
    binary_handle = NULL;
    pthread_mutex_unlock(&lock);
}

void *python_runtime_open_binary(const char *binary_dir, const char *name, char *err, size_t errsize)
{
    char path[PATH_MAX + 256];
    snprintf(path, sizeof path, "%s/%s", binary_dir, name);
    pthread_mutex_lock(&lock);
    if (!binary_handle) {
        binary_handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!binary_handle)
            message(err, errsize, "cannot load %s: %s", path, dlerror());
        else
            atexit(release_binary);  /* registered after pythonfmu's static objects: runs before them */
    }
    void *handle = binary_handle;
    pthread_mutex_unlock(&lock);
    return handle;
}

void *python_runtime_start(const void *symbol, const char *name, char *err, size_t errsize)
{
    char dir[PATH_MAX];
    if (binary_handle)
        return binary_handle;
    if (python_runtime_binary_dir(symbol, dir, sizeof dir, err, errsize) != 0
        || python_runtime_load(dir, err, errsize) != 0)
        return NULL;
    return python_runtime_open_binary(dir, name, err, errsize);
}

int python_runtime_binary_open(void)
{
    return binary_handle != NULL;
}
