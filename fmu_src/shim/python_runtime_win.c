/* Loading the Python that an FMU runs its model in, on Windows (see python_runtime.h).
 *
 * The Windows analogue of python_runtime.c, cross-compiled with mingw-w64 by fmu_build/win64.py into
 * binaries/win64/<modelIdentifier>.dll (FMI 3.0: binaries/x86_64-windows) with fmi2_shim.c or
 * fmi3_shim.c. The FMU carries the official embeddable CPython in binaries/<platform>/python/
 * (python311.dll, python3.dll, python311.zip, the standard library's .pyd modules, the Visual C++
 * runtime DLLs, Lib/site-packages with numpy). At the first instantiation this layer:
 *
 * 1. finds its own folder (GetModuleHandleExW on one of its functions, GetModuleFileNameW): no
 *    absolute path is compiled in, the FMU runs wherever the host unpacks it;
 * 2. loads vcruntime140.dll, vcruntime140_1.dll and msvcp140.dll from the runtime's folder, unless
 *    the process holds them already: a C host searches its own program's folder, not the FMU's,
 *    and a machine without the Visual C++ Redistributable has none;
 * 3. loads python3.dll and python311.dll by their full path (pythonfmu's DLL and numpy's modules
 *    then find them among the loaded modules by name), sets the legacy flags of an isolated start
 *    (no PYTHONPATH, PYTHONHOME or user site-packages of the host), sets the module search path
 *    to the runtime's own folders (Py_SetPath: no ._pth file, no registry, no PATH), starts Python
 *    without signal handlers and releases the GIL for pythonfmu's PyGILState calls;
 * 4. loads pythonfmu's DLL (pythonfmu-export.dll, beside this one).
 *
 * A process that already runs a Python (fmpy on Windows, or a second FMU of ours) keeps it: where
 * it is of the FMU's version, the FMU's standard library and site-packages are appended to
 * sys.path, as on Linux. It needs only KERNEL32 and msvcrt; the messages name what is missing. At
 * FreeLibrary (not at the process's exit) pythonfmu's interpreter holder is emptied (DllMain below).
 */
#include "shim_platform.h"
#include "python_runtime.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>
#include <ctype.h>

#define WPATH 4096

static SRWLOCK lock = SRWLOCK_INIT;
static int python_ready = 0;
static HMODULE binary_handle = NULL;
static int binary_released = 0;

static void message(char *err, size_t size, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(err, size, format, args);
    va_end(args);
}

static int to_wide(const char *utf8, wchar_t *out, int size)
{
    return MultiByteToWideChar(CP_UTF8, 0, utf8, -1, out, size) > 0;
}

static int to_utf8(const wchar_t *wide, char *out, int size)
{
    return WideCharToMultiByte(CP_UTF8, 0, wide, -1, out, size, NULL, NULL) > 0;
}

static int exists_w(const wchar_t *path)
{
    DWORD a = GetFileAttributesW(path);
    return a != INVALID_FILE_ATTRIBUTES && !(a & FILE_ATTRIBUTE_DIRECTORY);
}

int python_runtime_binary_dir(const void *symbol, char *dir, size_t size, char *err, size_t errsize)
{
    HMODULE module = NULL;
    wchar_t path[WPATH];
    if (!GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT,
                            (LPCWSTR)symbol, &module)) {
        message(err, errsize, "the FMU cannot find its own DLL (GetModuleHandleExW: error %lu)", GetLastError());
        return -1;
    }
    DWORD n = GetModuleFileNameW(module, path, WPATH);
    if (n == 0 || n >= WPATH) {
        message(err, errsize, "the FMU cannot find its own DLL's path (GetModuleFileNameW: error %lu)", GetLastError());
        return -1;
    }
    wchar_t *slash = wcsrchr(path, L'\\');
    wchar_t *other = wcsrchr(path, L'/');
    if (other > slash)
        slash = other;
    if (!slash) {
        message(err, errsize, "the FMU's DLL path has no folder");
        return -1;
    }
    *slash = L'\0';
    if (!to_utf8(path, dir, (int)size)) {
        message(err, errsize, "the FMU's folder path is too long");
        return -1;
    }
    return 0;
}

struct runtime_file {
    char runtime[32];   /* "standalone": the FMU carries its Python (folder) */
    char folder[260];   /* the runtime's prefix, relative to the binary's folder */
    char version[64];   /* X.Y.Z of the Windows runtime (win64_version=), else of the Linux one */
    char library[260];  /* python311.dll (win64_library=) */
    char packages[256];
    char path[PATH_MAX];
    int found;
};

static void read_runtime_file(const char *binary_dir, struct runtime_file *rt)
{
    memset(rt, 0, sizeof *rt);
    snprintf(rt->path, sizeof rt->path, "%s\\..\\..\\resources\\%s", binary_dir, PYTHON_RUNTIME_FILE);
    wchar_t wpath[WPATH];
    if (!to_wide(rt->path, wpath, WPATH))
        return;
    FILE *fh = _wfopen(wpath, L"r");
    if (!fh)
        return;
    rt->found = 1;
    char line[PATH_MAX + 64], version[64] = "", packages[256] = "";
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
        else if (!strcmp(line, "win64_version"))
            snprintf(rt->version, sizeof rt->version, "%s", value);
        else if (!strcmp(line, "win64_library"))
            snprintf(rt->library, sizeof rt->library, "%s", value);
        else if (!strcmp(line, "win64_packages"))
            snprintf(rt->packages, sizeof rt->packages, "%s", value);
        else if (!strcmp(line, "version"))
            snprintf(version, sizeof version, "%s", value);
        else if (!strcmp(line, "packages"))
            snprintf(packages, sizeof packages, "%s", value);
    }
    fclose(fh);
    if (!*rt->version)
        snprintf(rt->version, sizeof rt->version, "%s", version);
    if (!*rt->packages)
        snprintf(rt->packages, sizeof rt->packages, "%s", packages);
}

/* "3.11" from "3.11.9" or from "3.11.9 (tags/...)"; 0 if none */
static int minor_version(const char *text, char *out, size_t size)
{
    int major, minor;
    if (sscanf(text, "%d.%d", &major, &minor) != 2)
        return 0;
    snprintf(out, size, "%d.%d", major, minor);
    return 1;
}

/* The Python already in this process, if any: python3XX.dll of a Python host (fmpy), of a host
 * linked to Python, or of another FMU of ours. */
static HMODULE running_python(void)
{
    static const wchar_t *names[] = {L"python311.dll", L"python312.dll", L"python313.dll", L"python310.dll",
                                     L"python314.dll", L"python39.dll", L"python38.dll", NULL};
    for (int i = 0; names[i]; i++) {
        HMODULE m = GetModuleHandleW(names[i]);
        if (m)
            return m;
    }
    return NULL;
}

static void set_flag(HMODULE python, const char *name, int value)
{
    int *flag = (int *)GetProcAddress(python, name);
    if (flag)
        *flag = value;
}

/* Python code that appends the runtime's folders to sys.path where they are missing. */
static int append_runtime_paths(const char *home, const char *minor, char *code, size_t size)
{
    if (strpbrk(home, "'\n"))
        return -1;
    char nodot[16];
    int major = 3, m = 11;
    sscanf(minor, "%d.%d", &major, &m);
    snprintf(nodot, sizeof nodot, "%d%d", major, m);
    snprintf(code, size,
             "import sys\n"
             "for p in (r'%s\\python%s.zip', r'%s', r'%s\\Lib\\site-packages'):\n"
             "    if p not in sys.path: sys.path.append(p)\n", home, nodot, home, home);
    return 0;
}

/* Load <home>\<name> unless the process holds a module of that name already. */
static void load_runtime_dll(const wchar_t *home, const wchar_t *name)
{
    wchar_t path[WPATH];
    if (GetModuleHandleW(name))
        return;
    _snwprintf(path, WPATH, L"%ls\\%ls", home, name);
    path[WPATH - 1] = L'\0';
    if (exists_w(path))
        LoadLibraryExW(path, NULL, LOAD_WITH_ALTERED_SEARCH_PATH);
}

static int load_standalone(const char *binary_dir, const struct runtime_file *rt, char *err, size_t errsize)
{
    char home[PATH_MAX], minor[16];
    wchar_t whome[WPATH], library[WPATH], stable[WPATH], zip[WPATH], search[3 * WPATH + 64], program[WPATH],
        wname[260];
    if (!minor_version(rt->version, minor, sizeof minor)) {
        message(err, errsize, "resources\\%s names no Python version.", PYTHON_RUNTIME_FILE);
        return -1;
    }
    int major = 3, m = 11;
    sscanf(minor, "%d.%d", &major, &m);
    snprintf(home, sizeof home, "%s\\%s", binary_dir, *rt->folder ? rt->folder : "python");
    if (!to_wide(home, whome, WPATH)) {
        message(err, errsize, "the FMU's folder path is too long: %s", home);
        return -1;
    }
    if (*rt->library)
        to_wide(rt->library, wname, 260);
    else
        _snwprintf(wname, 260, L"python%d%d.dll", major, m);
    _snwprintf(library, WPATH, L"%ls\\%ls", whome, wname);
    _snwprintf(stable, WPATH, L"%ls\\python%d.dll", whome, major);
    _snwprintf(zip, WPATH, L"%ls\\python%d%d.zip", whome, major, m);
    const wchar_t *needed[] = {library, stable, zip, NULL};
    for (int i = 0; needed[i]; i++) {
        if (!exists_w(needed[i])) {
            char missing[PATH_MAX];
            to_utf8(needed[i], missing, sizeof missing);
            message(err, errsize, "the FMU's Python runtime is incomplete: %s is missing (was the FMU unpacked whole?).",
                    missing);
            return -1;
        }
    }
    /* the C++ runtime first, from the FMU: python311.dll, numpy's modules and pythonfmu's DLL need it */
    load_runtime_dll(whome, L"vcruntime140.dll");
    load_runtime_dll(whome, L"vcruntime140_1.dll");
    load_runtime_dll(whome, L"msvcp140.dll");
    if (!GetModuleHandleW(L"vcruntime140.dll")) {
        message(err, errsize, "cannot load vcruntime140.dll from the FMU's Python runtime %s (error %lu): the FMU "
                "needs 64-bit Windows 10 or 11, or 8.1 with its Universal C Runtime update.", home,
                GetLastError());
        return -1;
    }
    if (!LoadLibraryExW(stable, NULL, LOAD_WITH_ALTERED_SEARCH_PATH)) {
        message(err, errsize, "cannot load the FMU's python%d.dll from %s (error %lu).", major, home, GetLastError());
        return -1;
    }
    HMODULE python = LoadLibraryExW(library, NULL, LOAD_WITH_ALTERED_SEARCH_PATH);
    if (!python) {
        message(err, errsize, "cannot load the FMU's Python library python%d%d.dll from %s (Windows error %lu; the "
                "FMU needs 64-bit Windows 10 or 11, or 8.1 with its Universal C Runtime update).", major, m, home, GetLastError());
        return -1;
    }
    void (*set_home)(const wchar_t *) = (void (*)(const wchar_t *))GetProcAddress(python, "Py_SetPythonHome");
    void (*set_path)(const wchar_t *) = (void (*)(const wchar_t *))GetProcAddress(python, "Py_SetPath");
    void (*set_program)(const wchar_t *) = (void (*)(const wchar_t *))GetProcAddress(python, "Py_SetProgramName");
    void (*initialize)(int) = (void (*)(int))GetProcAddress(python, "Py_InitializeEx");
    void *(*save_thread)(void) = (void *(*)(void))GetProcAddress(python, "PyEval_SaveThread");
    int (*run)(const char *, void *) = (int (*)(const char *, void *))GetProcAddress(python, "PyRun_SimpleStringFlags");
    if (!set_home || !set_path || !initialize || !save_thread) {
        message(err, errsize, "the FMU's Python library lacks Py_SetPythonHome, Py_SetPath, Py_InitializeEx or "
                "PyEval_SaveThread.");
        return -1;
    }
    set_flag(python, "Py_IgnoreEnvironmentFlag", 1);   /* no PYTHONPATH, PYTHONHOME... of the host */
    set_flag(python, "Py_NoUserSiteDirectory", 1);     /* no %APPDATA%\Python\... site-packages */
    set_flag(python, "Py_UTF8Mode", 1);
    /* Python keeps these pointers: static copies */
    static wchar_t home_copy[WPATH], search_copy[3 * WPATH + 64], program_copy[WPATH];
    _snwprintf(search, sizeof search / sizeof *search, L"%ls;%ls;%ls\\Lib\\site-packages", zip, whome, whome);
    _snwprintf(program, WPATH, L"%ls\\python.exe", whome);
    wcscpy(home_copy, whome);
    wcscpy(search_copy, search);
    wcscpy(program_copy, program);
    if (set_program)
        set_program(program_copy);                     /* sys.executable: none of the host's Pythons */
    set_home(home_copy);
    set_path(search_copy);                             /* sys.path: the runtime's folders, nothing else */
    initialize(0);                                     /* no signal handlers: the host keeps Ctrl-C */
    (void)run;
    save_thread();                                     /* the GIL released for pythonfmu's PyGILState calls */
    return 0;
}

/* A Python already running in the process: where it is of the FMU's version, append the FMU's
 * standard library and site-packages to sys.path (after the host's own). */
static void offer_packages(HMODULE python, const char *binary_dir, const struct runtime_file *rt)
{
    const char *(*get_version)(void) = (const char *(*)(void))GetProcAddress(python, "Py_GetVersion");
    int (*ensure)(void) = (int (*)(void))GetProcAddress(python, "PyGILState_Ensure");
    void (*release)(int) = (void (*)(int))GetProcAddress(python, "PyGILState_Release");
    int (*run)(const char *, void *) = (int (*)(const char *, void *))GetProcAddress(python, "PyRun_SimpleStringFlags");
    char running[16], carried[16], home[PATH_MAX], code[4 * PATH_MAX + 256];
    snprintf(home, sizeof home, "%s\\%s", binary_dir, *rt->folder ? rt->folder : "python");
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
    HMODULE running = running_python();
    if (running) {
        int (*is_initialized)(void) = (int (*)(void))GetProcAddress(running, "Py_IsInitialized");
        if (!is_initialized || !is_initialized()) {
            message(err, errsize, "this process holds a Python library that is not started: the FMU cannot start "
                    "its own Python beside it. Start Python in the host first (Py_Initialize), or run the FMU in a "
                    "host that is not linked to Python.");
            return -1;
        }
        if (!strcmp(rt.runtime, "standalone"))
            offer_packages(running, binary_dir, &rt);
        python_ready = 1;
        return 0;
    }
    if (!rt.found) {
        message(err, errsize, "%s is missing: the FMU was not unpacked whole.", rt.path);
        return -1;
    }
    if (strcmp(rt.runtime, "standalone")) {
        message(err, errsize, "this FMU was built with --runtime host: on Windows it runs only in a Python host "
                "(fmpy) with numpy. Build it standalone (the default) to run it in any host.");
        return -1;
    }
    if (load_standalone(binary_dir, &rt, err, errsize) != 0)
        return -1;
    python_ready = 1;
    return 0;
}

int python_runtime_load(const char *binary_dir, char *err, size_t errsize)
{
    AcquireSRWLockExclusive(&lock);
    int status = load_locked(binary_dir, err, errsize);
    ReleaseSRWLockExclusive(&lock);
    return status;
}

/* When the host unloads this DLL (FreeLibrary) while the process goes on, pythonfmu's hold on the
 * interpreter is released while pythonfmu's DLL is still loaded (this DLL holds it), as on Linux.
 *
 * Not at the process's exit: Windows then detaches the DLLs in the reverse order of their
 * initialisation, so pythonfmu's DLL (loaded after this one) has already destroyed its static
 * holder, and emptying it again would write into freed memory (the fault the Linux layer avoids by
 * running first). pythonfmu's own teardown is in order by itself there: its DLL_PROCESS_DETACH
 * empties the holder before its static destructors run, or its static destructor releases it. */
static void release_binary(void)
{
    AcquireSRWLockExclusive(&lock);
    if (binary_handle) {
        void (*finalize)(void) = (void (*)(void))GetProcAddress(binary_handle, "finalizePythonInterpreter");
        if (finalize)
            finalize();
    }
    binary_handle = NULL;
    binary_released = 1;
    ReleaseSRWLockExclusive(&lock);
}

void *python_runtime_open_binary(const char *binary_dir, const char *name, char *err, size_t errsize)
{
    char path[PATH_MAX + 256];
    wchar_t wpath[WPATH];
    snprintf(path, sizeof path, "%s\\%s", binary_dir, name);
    AcquireSRWLockExclusive(&lock);
    if (!binary_handle && !binary_released) {
        if (!to_wide(path, wpath, WPATH)) {
            message(err, errsize, "the path %s is too long", path);
        } else {
            binary_handle = LoadLibraryExW(wpath, NULL, LOAD_WITH_ALTERED_SEARCH_PATH);
            if (!binary_handle)
                message(err, errsize, "cannot load %s (Windows error %lu)", path, GetLastError());
        }
    }
    void *handle = binary_handle;
    ReleaseSRWLockExclusive(&lock);
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

int python_runtime_check_location(const char *location, char *err, size_t errsize)
{
    if (!location)
        return 0;
    for (const unsigned char *p = (const unsigned char *)location; *p; p++) {
        int escaped = p[0] == '%' && p[1] && p[2] && strchr("89abcdefABCDEF", p[1]) && isxdigit(p[2]);
        if (*p >= 0x80 || escaped) {
            message(err, errsize, "the FMU is unpacked in a folder whose path has a character beyond ASCII (%s): "
                    "pythonfmu's Windows DLL, which this FMU runs on, cannot use it and would fail or crash. Unpack "
                    "the FMU in a folder with an ASCII path (letters A-Z, digits, spaces, - and _), or set the "
                    "host's temporary folder to one.", location);
            return -1;
        }
    }
    return 0;
}

/* reserved is NULL for FreeLibrary, non-NULL at the process's exit (see release_binary) */
BOOL WINAPI DllMain(HINSTANCE instance, DWORD reason, LPVOID reserved)
{
    (void)instance;
    if (reason == DLL_PROCESS_DETACH && reserved == NULL)
        release_binary();
    return TRUE;
}
