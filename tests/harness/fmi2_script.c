/* fmi2_script: drives one FMI 2.0 co-simulation binary through a script, the same C program on
 * every platform: built with gcc for linux64 (dlopen) and with MinGW for win64 (LoadLibrary, run
 * under Wine in the tests). tests/python/test_win64.py writes the scripts from the reference
 * cases and compares what the two platforms print.
 *
 *   fmi2_script SCRIPT OUT [SCRIPT OUT]...
 *
 * runs each SCRIPT in turn, writing what it gets into its OUT (one process for many scripts:
 * a Wine process takes half a second to start).
 * SCRIPT holds one command per line (numbers in hexadecimal IEEE-754 bits, so nothing is lost
 * in decimal conversion):
 *   load PATH                      load the shared library and resolve the FMI functions used
 *   instantiate NAME GUID URI      fmi2Instantiate (co-simulation, not visible, logging on)
 *   setup T0 T1                    fmi2SetupExperiment (no tolerance, stop time T1)
 *   enter / exit                   fmi2EnterInitializationMode / fmi2ExitInitializationMode
 *   real VR X | integer VR N | boolean VR B    fmi2Set<Type> of one variable
 *   get VR... ; geti VR... ; getb VR...        fmi2Get<Type>: one line "r|i|b v v ..." in OUT
 *   step T H                       fmi2DoStep(T, H, fmi2True)
 *   save FILE                      fmi2GetFMUstate + fmi2SerializeFMUstate into FILE
 *   restore FILE                   fmi2DeSerializeFMUstate of FILE + fmi2SetFMUstate
 *   free                           fmi2Terminate + fmi2FreeInstance
 *   # ...                          a comment
 * Every FMI call must return fmi2OK: otherwise the program prints the script line, the call and
 * its status (and the FMU's last log message) and exits with 1. */
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../fixtures/fmus/include/fmi2.h"

#ifdef _WIN32
#include <windows.h>
static void *open_library(const char *path) { return (void *)LoadLibraryA(path); }
static void *symbol(void *lib, const char *name) { return (void *)GetProcAddress((HMODULE)lib, name); }
static const char *library_error(void) {
    static char text[64];
    snprintf(text, sizeof text, "Windows error %lu", (unsigned long)GetLastError());
    return text;
}
#else
#include <dlfcn.h>
static void *open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(void *lib, const char *name) { return dlsym(lib, name); }
static const char *library_error(void) { return dlerror(); }
#endif

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*Setup)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*Call)(fmi2Component);
typedef void (*FreeInstance)(fmi2Component);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*SetInt)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Integer *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*GetInt)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Integer *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status (*GetState)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*SizeState)(fmi2Component, fmi2FMUstate, size_t *);
typedef fmi2Status (*Serialize)(fmi2Component, fmi2FMUstate, fmi2Byte *, size_t);
typedef fmi2Status (*Deserialize)(fmi2Component, const fmi2Byte *, size_t, fmi2FMUstate *);
typedef fmi2Status (*FreeState)(fmi2Component, fmi2FMUstate *);

static struct {
    Instantiate instantiate;
    Setup setup;
    Call enter, exit, terminate;
    FreeInstance free_instance;
    SetReal set_real;
    SetInt set_integer, set_boolean;
    GetReal get_real;
    GetInt get_integer, get_boolean;
    DoStep do_step;
    GetState get_state, set_state;
    SizeState size_state;
    Serialize serialize;
    Deserialize deserialize;
    FreeState free_state;
} fmi;

static const char *script_name;
static int line_no;
static char last_log[1024];

static void fail(const char *fmt, ...) {
    va_list args;
    va_start(args, fmt);
    fprintf(stderr, "fmi2_script: %s, line %d: ", script_name, line_no);
    vfprintf(stderr, fmt, args);
    va_end(args);
    if (last_log[0]) fprintf(stderr, " (the FMU's last message: %s)", last_log);
    fputc('\n', stderr);
    exit(1);
}

static void check(fmi2Status status, const char *call) {
    if (status != fmi2OK) fail("%s returned status %d", call, (int)status);
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env;
    (void)name;
    (void)status;
    (void)category;
    snprintf(last_log, sizeof last_log, "%s", message ? message : "");
}

static void *resolve(void *lib, const char *name) {
    void *f = symbol(lib, name);
    if (!f) fail("the library does not export %s", name);
    return f;
}

static void load(const char *path) {
    void *lib = open_library(path);
    if (!lib) fail("cannot load %s: %s", path, library_error());
    fmi.instantiate = (Instantiate)resolve(lib, "fmi2Instantiate");
    fmi.setup = (Setup)resolve(lib, "fmi2SetupExperiment");
    fmi.enter = (Call)resolve(lib, "fmi2EnterInitializationMode");
    fmi.exit = (Call)resolve(lib, "fmi2ExitInitializationMode");
    fmi.terminate = (Call)resolve(lib, "fmi2Terminate");
    fmi.free_instance = (FreeInstance)resolve(lib, "fmi2FreeInstance");
    fmi.set_real = (SetReal)resolve(lib, "fmi2SetReal");
    fmi.set_integer = (SetInt)resolve(lib, "fmi2SetInteger");
    fmi.set_boolean = (SetInt)resolve(lib, "fmi2SetBoolean");
    fmi.get_real = (GetReal)resolve(lib, "fmi2GetReal");
    fmi.get_integer = (GetInt)resolve(lib, "fmi2GetInteger");
    fmi.get_boolean = (GetInt)resolve(lib, "fmi2GetBoolean");
    fmi.do_step = (DoStep)resolve(lib, "fmi2DoStep");
    fmi.get_state = (GetState)resolve(lib, "fmi2GetFMUstate");
    fmi.set_state = (GetState)resolve(lib, "fmi2SetFMUstate");
    fmi.size_state = (SizeState)resolve(lib, "fmi2SerializedFMUstateSize");
    fmi.serialize = (Serialize)resolve(lib, "fmi2SerializeFMUstate");
    fmi.deserialize = (Deserialize)resolve(lib, "fmi2DeSerializeFMUstate");
    fmi.free_state = (FreeState)resolve(lib, "fmi2FreeFMUstate");
}

/* A double from its 16 hexadecimal digits of IEEE-754 bits. */
static double real_of(const char *hex) {
    uint64_t bits;
    double x;
    if (!hex || sscanf(hex, "%" SCNx64, &bits) != 1) fail("expected a hexadecimal double");
    memcpy(&x, &bits, sizeof x);
    return x;
}

static long integer_of(const char *text) {
    char *end;
    long n;
    if (!text) fail("expected an integer");
    n = strtol(text, &end, 10);
    if (*end) fail("expected an integer, found %s", text);
    return n;
}

static void save(fmi2Component c, const char *path) {
    fmi2FMUstate state = NULL;
    size_t size = 0;
    char *bytes;
    FILE *f;
    check(fmi.get_state(c, &state), "fmi2GetFMUstate");
    check(fmi.size_state(c, state, &size), "fmi2SerializedFMUstateSize");
    bytes = malloc(size ? size : 1);
    check(fmi.serialize(c, state, bytes, size), "fmi2SerializeFMUstate");
    check(fmi.free_state(c, &state), "fmi2FreeFMUstate");
    f = fopen(path, "wb");
    if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0) fail("cannot write %s", path);
    free(bytes);
}

static void restore(fmi2Component c, const char *path) {
    fmi2FMUstate state = NULL;
    long size;
    char *bytes;
    FILE *f = fopen(path, "rb");
    if (!f || fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0)
        fail("cannot read %s", path);
    bytes = malloc(size ? (size_t)size : 1);
    if (fread(bytes, 1, (size_t)size, f) != (size_t)size) fail("cannot read %s", path);
    fclose(f);
    check(fmi.deserialize(c, bytes, (size_t)size, &state), "fmi2DeSerializeFMUstate");
    check(fmi.set_state(c, state), "fmi2SetFMUstate");
    check(fmi.free_state(c, &state), "fmi2FreeFMUstate");
    free(bytes);
}

/* `get`, `geti` or `getb`: the listed value references, one line in `out`. */
static void get(fmi2Component c, const char *kind, FILE *out) {
    char *word;
    fputs(kind[3] == 'i' ? "i" : kind[3] == 'b' ? "b" : "r", out);
    while ((word = strtok(NULL, " \t\r\n"))) {
        fmi2ValueReference vr = (fmi2ValueReference)integer_of(word);
        if (kind[3] == '\0') {
            fmi2Real x;
            uint64_t bits;
            check(fmi.get_real(c, &vr, 1, &x), "fmi2GetReal");
            memcpy(&bits, &x, sizeof bits);
            fprintf(out, " %016" PRIx64, bits);
        } else {
            fmi2Integer n;
            check((kind[3] == 'i' ? fmi.get_integer : fmi.get_boolean)(c, &vr, 1, &n),
                  kind[3] == 'i' ? "fmi2GetInteger" : "fmi2GetBoolean");
            fprintf(out, " %d", (int)n);
        }
    }
    fputc('\n', out);
}

/* Runs one script, writing into `out_path`. */
static void run_script(const char *path, const char *out_path) {
    static char line[1 << 16];
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = NULL;
    FILE *script = fopen(path, "r");
    FILE *out = fopen(out_path, "wb"); /* "\n" on every platform */
    script_name = path;
    line_no = 0;
    last_log[0] = '\0';
    if (!script || !out) fail("cannot open %s or %s", path, out_path);
    while (fgets(line, sizeof line, script)) {
        char *cmd = strtok(line, " \t\r\n");
        line_no++;
        if (!cmd || cmd[0] == '#') continue;
        if (!strcmp(cmd, "load")) {
            load(strtok(NULL, "\r\n"));
        } else if (!strcmp(cmd, "instantiate")) {
            char *name = strtok(NULL, " "), *guid = strtok(NULL, " "), *uri = strtok(NULL, " \r\n");
            c = fmi.instantiate(name, fmi2CoSimulation, guid, uri, &callbacks, fmi2False, fmi2True);
            if (!c) fail("fmi2Instantiate returned NULL");
        } else if (!strcmp(cmd, "setup")) {
            double t0 = real_of(strtok(NULL, " ")), t1 = real_of(strtok(NULL, " \r\n"));
            check(fmi.setup(c, fmi2False, 0.0, t0, fmi2True, t1), "fmi2SetupExperiment");
        } else if (!strcmp(cmd, "enter")) {
            check(fmi.enter(c), "fmi2EnterInitializationMode");
        } else if (!strcmp(cmd, "exit")) {
            check(fmi.exit(c), "fmi2ExitInitializationMode");
        } else if (!strcmp(cmd, "real")) {
            fmi2ValueReference vr = (fmi2ValueReference)integer_of(strtok(NULL, " "));
            fmi2Real x = real_of(strtok(NULL, " \r\n"));
            check(fmi.set_real(c, &vr, 1, &x), "fmi2SetReal");
        } else if (!strcmp(cmd, "integer") || !strcmp(cmd, "boolean")) {
            fmi2ValueReference vr = (fmi2ValueReference)integer_of(strtok(NULL, " "));
            fmi2Integer n = (fmi2Integer)integer_of(strtok(NULL, " \r\n"));
            check((cmd[0] == 'i' ? fmi.set_integer : fmi.set_boolean)(c, &vr, 1, &n),
                  cmd[0] == 'i' ? "fmi2SetInteger" : "fmi2SetBoolean");
        } else if (!strncmp(cmd, "get", 3)) {
            get(c, cmd, out);
        } else if (!strcmp(cmd, "step")) {
            double t = real_of(strtok(NULL, " ")), h = real_of(strtok(NULL, " \r\n"));
            check(fmi.do_step(c, t, h, fmi2True), "fmi2DoStep");
        } else if (!strcmp(cmd, "save")) {
            save(c, strtok(NULL, "\r\n"));
        } else if (!strcmp(cmd, "restore")) {
            restore(c, strtok(NULL, "\r\n"));
        } else if (!strcmp(cmd, "free")) {
            check(fmi.terminate(c), "fmi2Terminate");
            fmi.free_instance(c);
            c = NULL;
        } else {
            fail("unknown command %s", cmd);
        }
    }
    fclose(script);
    if (fclose(out) != 0) fail("cannot write %s", out_path);
}

int main(int argc, char **argv) {
    int i;
    if (argc < 3 || argc % 2 == 0) {
        fprintf(stderr, "usage: fmi2_script SCRIPT OUT [SCRIPT OUT]...\n");
        return 2;
    }
    for (i = 1; i + 1 < argc; i += 2) run_script(argv[i], argv[i + 1]);
    return 0;
}
