/* What the FMI 2.0 and FMI 3.0 layers (fmi2_shim.c, fmi3_shim.c) share to enforce the standard:
 * the FMU's table of variables, the header of a serialized FMU state, the tracking of state
 * pointers, the step-time tolerance, message formatting and the host's log (which messages pass,
 * a refused call's Error line). Header only (every function is
 * static), plain C types only (no FMI types), Linux (gcc) and Windows (mingw-w64) alike: include
 * it after shim_platform.h.
 *
 * API
 *
 * Variables table: resources/fmi_variables.tsv, written by fmu_build/shim.py from the FMU's own
 * modelDescription.xml, one line per model variable:
 *     value_reference TAB type TAB causality TAB variability TAB initial TAB name TAB n_values
 * (type as the modelDescription names it: Real/Integer/Boolean/String in FMI 2.0, Float64/Int32/...
 * in FMI 3.0; initial may be empty; n_values: the number of values, the product of the variable's
 * Dimension starts (FMI 3.0 arrays), 1 for a scalar, 0 where a structural parameter sizes the array;
 * a table of 6 columns gives 0 there; lines starting with '#' and empty lines are skipped).
 *
 *   typedef struct { unsigned int vr; char type[16]; char causality[24]; char variability[16];
 *                    char initial[16]; char *name; size_t n_values; } ShimVariable;
 *       n_values: 0 where the number is not known (not checked).
 *   typedef struct { ShimVariable *items; size_t n; } ShimVariables;
 *
 *   int shim_variables_load(ShimVariables *t, const char *resource_location, char *err, size_t size);
 *       Reads <resources>/fmi_variables.tsv. resource_location: FMI 2.0's fmuResourceLocation (a URI:
 *       file:///path, file:/path, file://localhost/path, file:///C:/path, on Windows file://server/share/path;
 *       %-escapes decoded) or
 *       FMI 3.0's resourcePath (a plain path, with or without its trailing separator).
 *       0, or -1 with a message in err (the file's path and what is wrong); *t is then empty.
 *   int shim_resource_path(const char *resource_location, const char *file, char *path, size_t size);
 *       The path of `file` in the resources folder (what shim_variables_load opens). 0, or -1.
 *   const ShimVariable *shim_variable_find(const ShimVariables *t, const char *type, unsigned int vr);
 *       The variable with value reference vr and that type ("Real", "Float64", ...; NULL: any type,
 *       as in FMI 3.0 where value references are unique across types), or NULL.
 *   void shim_variables_free(ShimVariables *t);
 *
 *   enum { SHIM_BEFORE_INITIALIZATION, SHIM_INITIALIZING, SHIM_RUNNING };
 *   int shim_may_set(const ShimVariable *v, int phase, const char *exit_initialization,
 *                    char *why, size_t size);
 *       1 where the variable may be set in that phase (before initialization: FMI 2.0's Instantiated,
 *       FMI 3.0's Instantiated; initializing: InitializationMode; running: StepComplete/StepMode and
 *       the like). 0 with the reason in why, e.g. "is an output: it cannot be set" or "is a fixed
 *       parameter: it can be set only before fmi2ExitInitializationMode" (exit_initialization names
 *       that function). Rules: inputs and parameters (fixed or tunable) may be set before and during
 *       initialization; once running, inputs and tunable parameters only; outputs, locals,
 *       calculated parameters, independents and constants never.
 *
 * Serialized state header (SHIM_STATE_HEADER_SIZE = 40 bytes, little-endian whatever the machine):
 *     8 bytes magic "SLWFMUST", 4 bytes format version (SHIM_STATE_FORMAT = 2), 4 bytes the payload's
 *     CRC-32 (the checksum of zlib and PNG), 8 bytes FNV-1a 64-bit hash of the FMU's GUID /
 *     instantiation token, 8 bytes the communication time (IEEE double), 8 bytes the payload length;
 *     then the payload (pythonfmu's bytes).
 *
 *   size_t shim_state_header_size(void);
 *   void shim_state_header_write(unsigned char *bytes, const char *token, double time, size_t payload);
 *       Call it once the payload is in place after the header: the checksum covers it.
 *   int shim_state_header_check(const unsigned char *bytes, size_t size, const char *token,
 *                               double *time, const unsigned char **payload, size_t *payload_size,
 *                               char *why, size_t why_size);
 *       SHIM_STATE_OK (0), or the first check that failed, with a sentence in why:
 *       SHIM_STATE_SHORT   "no header: N bytes are fewer than the header's 40"
 *       SHIM_STATE_MAGIC   "no header: wrong magic"
 *       SHIM_STATE_VERSION "another format version: V, this FMU reads version 1"
 *       SHIM_STATE_TOKEN   "another FMU's state: its GUID / instantiation token differs"
 *       SHIM_STATE_LENGTH  "wrong length: the header announces P bytes of state, N follow it"
 *       SHIM_STATE_CHECKSUM "the content's checksum does not match: corrupted"
 *   unsigned long shim_crc32(const unsigned char *bytes, size_t n);   the payload's checksum
 *
 * FMU state pointers handed to the host (each layer's own small struct, not the inner binary's):
 *   typedef struct ShimState { unsigned int magic; double time; int phase; void *inner; struct ShimState *next; } ShimState;
 *   ShimState *shim_state_add(ShimState **list, void *inner, double time);    NULL: out of memory
 *   ShimState *shim_state_lookup(ShimState *list, const void *pointer);      NULL: not one of ours
 *       (compares pointers only: never reads memory a foreign pointer points to)
 *   void shim_state_remove(ShimState **list, ShimState *s);                   frees the wrapper only
 *
 * Time and messages:
 *   int shim_same_time(double expected, double got);
 *       1 where |got - expected| <= 1e-9 * max(1, |expected|) + 1e-12 (the step continuity rule).
 *   const char *shim_double(char buf[32], double x);
 *       x with 15 significant digits, as people write it ("5", "0.1", "2.3" for 2.3000000000000003,
 *       "1e-05"): enough to tell apart two times shim_same_time tells apart.
 *   void shim_format(char *buf, size_t size, const char *format, ...);
 *       snprintf that always terminates (truncates). Use %u/%lu/%s/%g, not %zu (old msvcrt).
 *
 * The host's log (what both layers pass on, and how; each layer calls its host's logger in a sink):
 *   typedef void (*ShimLogSink)(void *layer, int status, const char *category, const char *text);
 *       The layer's call of its host's logger (FMI 2.0's and 3.0's differ): status is the layer's
 *       fmi2Status / fmi3Status (OK 0, Warning 1, Discard 2, Error 3, Fatal 4 in both), text plain text.
 *   typedef struct { ShimLogSink sink; void *layer; int on; size_t n_categories; char **categories; } ShimLog;
 *       sink NULL: the host gave no logger; layer: the sink's first argument; on: loggingOn;
 *       categories: fmiXSetDebugLogging's (none: every category).
 *   int shim_log_wanted(const ShimLog *log, int status, const char *category);
 *       1 where a message goes to the host: an Error or worse always, another one where logging is on
 *       and its category is one of the categories (or none were given).
 *   int shim_log_set(ShimLog *log, int on, size_t n, const char *const categories[]);
 *       fmiXSetDebugLogging's loggingOn and categories (copied; a NULL category is ""). 0, or -1 out
 *       of memory, the log unchanged.
 *   void shim_log_free(ShimLog *log);                                     frees the categories
 *   void shim_log_text(const ShimLog *log, int status, const char *category, const char *text);
 *       Passes text to the sink where shim_log_wanted.
 *   int shim_refuse(const ShimLog *log, const char *format, ...);
 *       A call refused by the layer: the formatted message (at most 1023 characters) as one Error
 *       line of category "logStatusError". Returns SHIM_LOG_ERROR (fmi2Error, fmi3Error).
 */
#ifndef SLEWING_SHIM_RULES_H
#define SLEWING_SHIM_RULES_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SHIM_VARIABLES_FILE "fmi_variables.tsv"

/* ---- messages --------------------------------------------------------------------------- */
static void shim_format(char *buf, size_t size, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4), unused))
#endif
    ;
static void shim_format(char *buf, size_t size, const char *format, ...)
{
    if (!buf || size == 0)
        return;
    va_list ap;
    va_start(ap, format);
    vsnprintf(buf, size, format, ap);
    va_end(ap);
    buf[size - 1] = '\0';
}

#if defined(__GNUC__)
#define SHIM_UNUSED __attribute__((unused))
#else
#define SHIM_UNUSED
#endif

static SHIM_UNUSED const char *shim_double(char buf[32], double x)
{
    snprintf(buf, 32, "%.15g", x);
    return buf;
}

static SHIM_UNUSED int shim_same_time(double expected, double got)
{
    double scale = expected < 0 ? -expected : expected, gap = got - expected;  /* no libm */
    if (scale < 1.0)
        scale = 1.0;
    if (gap < 0)
        gap = -gap;
    return gap <= 1e-9 * scale + 1e-12;  /* false for NaN */
}

/* ---- the host's log ------------------------------------------------------------------------ */
#define SHIM_LOG_ERROR 3  /* fmi2Error, fmi3Error */

typedef void (*ShimLogSink)(void *layer, int status, const char *category, const char *text);

typedef struct {
    ShimLogSink sink;      /* NULL: the host gave no logger */
    void *layer;           /* the sink's first argument: the layer's instance */
    int on;                /* loggingOn */
    size_t n_categories;   /* 0: every category */
    char **categories;
} ShimLog;

static SHIM_UNUSED int shim_log_wanted(const ShimLog *log, int status, const char *category)
{
    if (status >= SHIM_LOG_ERROR)
        return 1;
    if (!log->on)
        return 0;
    if (log->n_categories == 0)
        return 1;
    for (size_t i = 0; i < log->n_categories; i++)
        if (category && !strcmp(category, log->categories[i]))
            return 1;
    return 0;
}

static void shim_log_free(ShimLog *log)
{
    for (size_t i = 0; i < log->n_categories; i++)
        free(log->categories[i]);
    free(log->categories);
    log->categories = NULL;
    log->n_categories = 0;
}

static SHIM_UNUSED int shim_log_set(ShimLog *log, int on, size_t n, const char *const categories[])
{
    char **copy = NULL;
    if (n > 0) {
        if (!(copy = (char **)calloc(n, sizeof(char *))))
            return -1;
        for (size_t i = 0; i < n; i++) {
            const char *category = categories[i] ? categories[i] : "";
            if (!(copy[i] = (char *)malloc(strlen(category) + 1))) {
                for (size_t j = 0; j < i; j++)
                    free(copy[j]);
                free(copy);
                return -1;
            }
            strcpy(copy[i], category);
        }
    }
    shim_log_free(log);
    log->on = on;
    log->categories = copy;
    log->n_categories = copy ? n : 0;
    return 0;
}

static SHIM_UNUSED void shim_log_text(const ShimLog *log, int status, const char *category, const char *text)
{
    if (log->sink && shim_log_wanted(log, status, category))
        log->sink(log->layer, status, category, text);
}

static int shim_refuse(const ShimLog *log, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3), unused))
#endif
    ;
static int shim_refuse(const ShimLog *log, const char *format, ...)
{
    char text[1024];
    va_list ap;
    va_start(ap, format);
    vsnprintf(text, sizeof text, format, ap);
    va_end(ap);
    text[sizeof text - 1] = '\0';
    shim_log_text(log, SHIM_LOG_ERROR, "logStatusError", text);
    return SHIM_LOG_ERROR;
}

/* ---- variables table -------------------------------------------------------------------- */
typedef struct {
    unsigned int vr;
    char type[16];
    char causality[24];
    char variability[16];
    char initial[16];
    char *name;
    size_t n_values;  /* the number of values (1: a scalar); 0: not known */
} ShimVariable;

typedef struct {
    ShimVariable *items;  /* sorted by vr, then as in the file */
    size_t n;
} ShimVariables;

static int shim_hex_digit(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

static SHIM_UNUSED int shim_resource_path(const char *location, const char *file, char *path, size_t size)
{
    if (!location || !file || !path || size == 0)
        return -1;
    const char *p = location;
    int uri = strncmp(p, "file:", 5) == 0;
    size_t n = 0;
    if (uri) {
        p += 5;
        if (strncmp(p, "//", 2) == 0) {           /* file://authority/path */
            p += 2;
            const char *slash = strchr(p, '/');
            if (!slash)
                return -1;
#ifdef _WIN32
            if (slash != p && strncmp(p, "localhost/", 10) != 0) {
                if (size < 3)
                    return -1;
                path[n++] = '/';                  /* file://server/share -> //server/share */
                path[n++] = '/';
                slash = p;
            }
#endif
            p = slash;                            /* an empty authority or localhost: dropped */
        }
#ifdef _WIN32
        if (p[0] == '/' && p[1] && (p[2] == ':' || p[2] == '|'))
            p++;                                  /* file:///C:/dir -> C:/dir */
#endif
        for (; *p && n + 1 < size; p++) {
            int hi, lo;
            if (*p == '%' && (hi = shim_hex_digit(p[1])) >= 0 && (lo = shim_hex_digit(p[2])) >= 0) {
                path[n++] = (char)(hi * 16 + lo);
                p += 2;
            } else {
                path[n++] = *p;
            }
        }
        if (*p)
            return -1;
    } else {
        n = strlen(p);
        if (n + 1 > size)
            return -1;
        memcpy(path, p, n);
    }
    if (n > 0 && path[n - 1] != '/' && path[n - 1] != '\\') {
        if (n + 2 > size)
            return -1;
        path[n++] = '/';
    }
    size_t f = strlen(file);
    if (n + f + 1 > size)
        return -1;
    memcpy(path + n, file, f + 1);
    return 0;
}

static int shim_variable_compare(const void *a, const void *b)
{
    const ShimVariable *x = (const ShimVariable *)a, *y = (const ShimVariable *)b;
    if (x->vr != y->vr)
        return x->vr < y->vr ? -1 : 1;
    return x < y ? -1 : (x > y);
}

static void shim_variables_free(ShimVariables *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->n; i++)
        free(t->items[i].name);
    free(t->items);
    t->items = NULL;
    t->n = 0;
}

static void shim_copy_field(char *dst, size_t size, const char *src)
{
    size_t n = strlen(src);
    if (n >= size)
        n = size - 1;
    memcpy(dst, src, n);
    dst[n] = '\0';
}

static SHIM_UNUSED int shim_variables_load(ShimVariables *t, const char *resource_location, char *err, size_t size)
{
    char path[4096];
    t->items = NULL;
    t->n = 0;
    if (!resource_location || shim_resource_path(resource_location, SHIM_VARIABLES_FILE, path, sizeof path) != 0) {
        shim_format(err, size, "the FMU's resource location (%s) is not a folder this FMU can read %s from",
                    resource_location ? resource_location : "none given", SHIM_VARIABLES_FILE);
        return -1;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        shim_format(err, size, "the FMU's table of variables %s is missing (was the FMU unpacked whole, and built by "
                    "build_fmu.py?)", path);
        return -1;
    }
    size_t capacity = 1 << 16, length = 0;
    char *text = (char *)malloc(capacity + 1);
    while (text) {
        size_t got = fread(text + length, 1, capacity - length, f);
        length += got;
        if (length < capacity)
            break;
        char *bigger = (char *)realloc(text, 2 * capacity + 1);
        if (!bigger) {
            free(text);
            text = NULL;
            break;
        }
        text = bigger;
        capacity *= 2;
    }
    fclose(f);
    if (!text) {
        shim_format(err, size, "out of memory reading %s", path);
        return -1;
    }
    text[length] = '\0';
    size_t lines = 1;
    for (size_t i = 0; i < length; i++)
        lines += text[i] == '\n';
    t->items = (ShimVariable *)calloc(lines, sizeof(ShimVariable));
    if (!t->items) {
        free(text);
        shim_format(err, size, "out of memory reading %s", path);
        return -1;
    }
    int status = 0;
    size_t number = 0;
    for (char *line = text; line && *line && status == 0;) {
        char *next = strchr(line, '\n');
        if (next)
            *next++ = '\0';
        number++;
        size_t n = strlen(line);
        if (n > 0 && line[n - 1] == '\r')
            line[--n] = '\0';
        if (n == 0 || line[0] == '#') {
            line = next;
            continue;
        }
        char *field[7];
        int k = 0;
        field[k++] = line;
        for (char *q = line; *q && k < 7; q++)
            if (*q == '\t') {
                *q = '\0';
                field[k++] = q + 1;
            }
        char *end = NULL, *end_values = NULL;
        unsigned long vr = k >= 6 ? strtoul(field[0], &end, 10) : 0;
        unsigned long long n_values = k == 7 ? strtoull(field[6], &end_values, 10) : 0;
        if (k < 6 || end == field[0] || *end != '\0' ||
            (k == 7 && (end_values == field[6] || *end_values != '\0' || field[6][0] == '-'))) {
            shim_format(err, size, "%s, line %lu: not value_reference<TAB>type<TAB>causality<TAB>variability<TAB>"
                        "initial<TAB>name<TAB>n_values", path, (unsigned long)number);
            status = -1;
            break;
        }
        ShimVariable *v = &t->items[t->n];
        v->vr = (unsigned int)vr;
        shim_copy_field(v->type, sizeof v->type, field[1]);
        shim_copy_field(v->causality, sizeof v->causality, field[2]);
        shim_copy_field(v->variability, sizeof v->variability, field[3]);
        shim_copy_field(v->initial, sizeof v->initial, field[4]);
        v->name = (char *)malloc(strlen(field[5]) + 1);
        if (!v->name) {
            shim_format(err, size, "out of memory reading %s", path);
            status = -1;
            break;
        }
        strcpy(v->name, field[5]);
        v->n_values = (size_t)n_values;
        t->n++;
        line = next;
    }
    free(text);
    if (status != 0) {
        shim_variables_free(t);
        return -1;
    }
    qsort(t->items, t->n, sizeof(ShimVariable), shim_variable_compare);
    return 0;
}

static SHIM_UNUSED const ShimVariable *shim_variable_find(const ShimVariables *t, const char *type, unsigned int vr)
{
    if (!t || t->n == 0)
        return NULL;
    size_t lo = 0, hi = t->n;  /* first item with items[i].vr >= vr */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (t->items[mid].vr < vr)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (size_t i = lo; i < t->n && t->items[i].vr == vr; i++)
        if (!type || !strcmp(t->items[i].type, type))
            return &t->items[i];
    return NULL;
}

enum { SHIM_BEFORE_INITIALIZATION, SHIM_INITIALIZING, SHIM_RUNNING };

static SHIM_UNUSED int shim_may_set(const ShimVariable *v, int phase, const char *exit_initialization, char *why,
                                    size_t size)
{
    const char *c = v->causality, *var = v->variability;
    if (!strcmp(var, "constant")) {
        shim_format(why, size, "is a constant: it cannot be set");
        return 0;
    }
    if (!strcmp(c, "input"))
        return 1;
    if (!strcmp(c, "parameter")) {
        if (phase != SHIM_RUNNING || !strcmp(var, "tunable"))
            return 1;
        shim_format(why, size, "is a %s parameter: it can be set only before %s", var[0] ? var : "fixed",
                    exit_initialization);
        return 0;
    }
    if (!strcmp(c, "output"))
        shim_format(why, size, "is an output: it cannot be set");
    else if (!strcmp(c, "calculatedParameter"))
        shim_format(why, size, "is a calculated parameter: it cannot be set");
    else if (!strcmp(c, "independent"))
        shim_format(why, size, "is the independent variable: it cannot be set");
    else if (!strcmp(c, "structuralParameter")) {
        if (phase != SHIM_RUNNING)
            return 1;
        shim_format(why, size, "is a structural parameter: it can be set only before %s", exit_initialization);
    } else
        shim_format(why, size, "is a %s variable: it cannot be set", c[0] ? c : "local");
    return 0;
}

/* ---- serialized state header ------------------------------------------------------------ */
#define SHIM_STATE_HEADER_SIZE 40
#define SHIM_STATE_MAGIC_TEXT "SLWFMUST"
#define SHIM_STATE_FORMAT 2u
enum { SHIM_STATE_OK = 0, SHIM_STATE_SHORT, SHIM_STATE_MAGIC, SHIM_STATE_VERSION, SHIM_STATE_TOKEN, SHIM_STATE_LENGTH,
       SHIM_STATE_CHECKSUM };

static SHIM_UNUSED size_t shim_state_header_size(void) { return SHIM_STATE_HEADER_SIZE; }

static unsigned long long shim_token_hash(const char *token)
{
    unsigned long long h = 14695981039346656037ull;  /* FNV-1a 64 */
    for (const unsigned char *p = (const unsigned char *)(token ? token : ""); *p; p++) {
        h ^= *p;
        h *= 1099511628211ull;
    }
    return h;
}

/* CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320: zlib's crc32), bitwise: no table */
static SHIM_UNUSED unsigned long shim_crc32(const unsigned char *bytes, size_t n)
{
    unsigned long crc = 0xffffffffUL;
    for (size_t i = 0; i < n; i++) {
        crc ^= bytes[i];
        for (int k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xedb88320UL & (0UL - (crc & 1UL)));
    }
    return (crc ^ 0xffffffffUL) & 0xffffffffUL;
}

static void shim_put_u64(unsigned char *p, unsigned long long x)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(x >> (8 * i));
}

static unsigned long long shim_get_u64(const unsigned char *p)
{
    unsigned long long x = 0;
    for (int i = 0; i < 8; i++)
        x |= (unsigned long long)p[i] << (8 * i);
    return x;
}

static SHIM_UNUSED void shim_state_header_write(unsigned char *bytes, const char *token, double time, size_t payload)
{
    unsigned long long bits;
    memcpy(bytes, SHIM_STATE_MAGIC_TEXT, 8);
    /* format version (4 bytes), then the payload's CRC-32 (4 bytes) */
    shim_put_u64(bytes + 8, SHIM_STATE_FORMAT | ((unsigned long long)shim_crc32(bytes + SHIM_STATE_HEADER_SIZE, payload)
                                                 << 32));
    shim_put_u64(bytes + 16, shim_token_hash(token));
    memcpy(&bits, &time, 8);
    shim_put_u64(bytes + 24, bits);
    shim_put_u64(bytes + 32, (unsigned long long)payload);
}

static SHIM_UNUSED int shim_state_header_check(const unsigned char *bytes, size_t size, const char *token,
                                               double *time, const unsigned char **payload, size_t *payload_size,
                                               char *why, size_t why_size)
{
    if (!bytes || size < SHIM_STATE_HEADER_SIZE) {
        shim_format(why, why_size, "no header: %lu bytes are fewer than the header's %d", (unsigned long)size,
                    SHIM_STATE_HEADER_SIZE);
        return SHIM_STATE_SHORT;
    }
    if (memcmp(bytes, SHIM_STATE_MAGIC_TEXT, 8) != 0) {
        shim_format(why, why_size, "no header: wrong magic");
        return SHIM_STATE_MAGIC;
    }
    unsigned long long version = shim_get_u64(bytes + 8) & 0xffffffffull;
    if (version != SHIM_STATE_FORMAT) {
        shim_format(why, why_size, "another format version: %lu, this FMU reads version %u", (unsigned long)version,
                    SHIM_STATE_FORMAT);
        return SHIM_STATE_VERSION;
    }
    if (shim_get_u64(bytes + 16) != shim_token_hash(token)) {
        shim_format(why, why_size, "another FMU's state: its GUID / instantiation token differs");
        return SHIM_STATE_TOKEN;
    }
    unsigned long long announced = shim_get_u64(bytes + 32);
    if (announced != (unsigned long long)(size - SHIM_STATE_HEADER_SIZE)) {
        shim_format(why, why_size, "wrong length: the header announces %.0f bytes of state, %lu follow it",
                    (double)announced, (unsigned long)(size - SHIM_STATE_HEADER_SIZE));
        return SHIM_STATE_LENGTH;
    }
    if ((shim_get_u64(bytes + 8) >> 32) != shim_crc32(bytes + SHIM_STATE_HEADER_SIZE, size - SHIM_STATE_HEADER_SIZE)) {
        shim_format(why, why_size, "the content's checksum does not match: corrupted");
        return SHIM_STATE_CHECKSUM;
    }
    unsigned long long bits = shim_get_u64(bytes + 24);
    if (time)
        memcpy(time, &bits, 8);
    if (payload)
        *payload = bytes + SHIM_STATE_HEADER_SIZE;
    if (payload_size)
        *payload_size = size - SHIM_STATE_HEADER_SIZE;
    return SHIM_STATE_OK;
}

/* ---- FMU state pointers ----------------------------------------------------------------- */
#define SHIM_STATE_WRAPPER_MAGIC 0x53544154u  /* "STAT" */

typedef struct ShimState {
    unsigned int magic;
    double time;            /* the communication time the state was taken at */
    int phase;              /* the layer's state machine state it was taken in (0: a deserialized state,
                             * taken by a running instance); fmiSetFMUstate returns the instance to it */
    void *inner;            /* the inner binary's state */
    struct ShimState *next;
} ShimState;

static SHIM_UNUSED ShimState *shim_state_add(ShimState **list, void *inner, double time)
{
    ShimState *s = (ShimState *)calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->magic = SHIM_STATE_WRAPPER_MAGIC;
    s->time = time;
    s->inner = inner;
    s->next = *list;
    *list = s;
    return s;
}

static SHIM_UNUSED ShimState *shim_state_lookup(ShimState *list, const void *pointer)
{
    for (ShimState *s = list; s && pointer; s = s->next)
        if ((const void *)s == pointer)
            return s->magic == SHIM_STATE_WRAPPER_MAGIC ? s : NULL;
    return NULL;
}

static SHIM_UNUSED void shim_state_remove(ShimState **list, ShimState *s)
{
    for (ShimState **p = list; *p; p = &(*p)->next)
        if (*p == s) {
            *p = s->next;
            s->magic = 0;
            free(s);
            return;
        }
}

#endif
