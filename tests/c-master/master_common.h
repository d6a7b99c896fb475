/* What the C masters (master.c: FMI 2.0, master_fmi3.c: FMI 3.0) share: loading, symbol lookup and
 * the parsing of their value-reference arguments. A value reference is an unsigned int in
 * both standards (fmi2ValueReference; fmi3ValueReference = uint32_t). */
#ifndef MASTER_COMMON_H
#define MASTER_COMMON_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VARS 256

/* A list of value-reference pairs (src:dst) or single references. */
typedef struct {
    size_t n;
    unsigned int src[MAX_VARS], dst[MAX_VARS];
} Links;

#ifdef _WIN32
/* win64 (MinGW), run under Wine by tests/test_fmi3.py. */
#include <windows.h>

static void *open_library(const char *path) {
    HMODULE lib = LoadLibraryA(path);
    if (!lib) {
        fprintf(stderr, "LoadLibrary %s: error %lu\n", path, (unsigned long)GetLastError());
        exit(1);
    }
    return (void *)lib;
}

static void *symbol(void *lib, const char *name) {
    void *f = (void *)GetProcAddress((HMODULE)lib, name);
#else
#include <dlfcn.h>

static void *open_library(const char *path) {
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen %s: %s\n", path, dlerror());
        exit(1);
    }
    return lib;
}

static void *symbol(void *lib, const char *name) {
    void *f = dlsym(lib, name);
#endif
    if (!f) {
        fprintf(stderr, "missing symbol %s\n", name);
        exit(1);
    }
    return f;
}

static void parse(Links *l, const char *text, int pairs) {
    char *copy = strdup(text), *save = NULL;
    l->n = 0;
    for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (l->n == MAX_VARS) {
            fprintf(stderr, "more than %d references\n", MAX_VARS);
            exit(1);
        }
        char *end;
        l->src[l->n] = (unsigned int)strtoul(tok, &end, 10);
        l->dst[l->n] = l->src[l->n];
        if (pairs) {
            if (*end != ':') {
                fprintf(stderr, "bad link %s (want src:dst)\n", tok);
                exit(1);
            }
            l->dst[l->n] = (unsigned int)strtoul(end + 1, &end, 10);
        }
        if (*end != '\0') {
            fprintf(stderr, "bad reference %s\n", tok);
            exit(1);
        }
        l->n++;
    }
    free(copy);
}

#endif
