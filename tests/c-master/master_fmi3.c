/* The FMI 3.0 counterpart of master.c: plant + controller as FMI 3.0 Co-Simulation
 * instances, Gauss-Seidel with the timing of tailsim's ClosedLoop (see master.c). Built
 * for the host, for aarch64 and for win64 (MinGW) by tests/test_fmi3.py, which flies the
 * libraries of dist/fmi3/<id>.fmu (binaries/x86_64-linux; binaries/aarch64-linux under
 * qemu-user; binaries/x86_64-windows under Wine).
 *
 * usage: master_fmi3 PLANT.so PLANT_TOKEN CONTROLLER.so CONTROLLER_TOKEN H T_STOP
 *                    TO_CONTROLLER TO_PLANT RECORD
 * (arguments, output and exit status as master.c; the tokens are the instantiationTokens). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "master_common.h"

typedef struct {
    void *lib;
    fmi3Instance c;
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3EnterInitializationModeTYPE *enter_init;
    fmi3ExitInitializationModeTYPE *exit_init;
    fmi3GetFloat64TYPE *get;
    fmi3SetFloat64TYPE *set;
    fmi3DoStepTYPE *do_step;
    fmi3TerminateTYPE *terminate;
    fmi3FreeInstanceTYPE *free_instance;
} Unit;

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    fprintf(stderr, "[%s] %d %s: %s\n", (const char *)env, (int)status, category, message);
}

static void load(Unit *u, const char *path) {
    u->lib = open_library(path);
    u->instantiate = (fmi3InstantiateCoSimulationTYPE *)symbol(u->lib, "fmi3InstantiateCoSimulation");
    u->enter_init = (fmi3EnterInitializationModeTYPE *)symbol(u->lib, "fmi3EnterInitializationMode");
    u->exit_init = (fmi3ExitInitializationModeTYPE *)symbol(u->lib, "fmi3ExitInitializationMode");
    u->get = (fmi3GetFloat64TYPE *)symbol(u->lib, "fmi3GetFloat64");
    u->set = (fmi3SetFloat64TYPE *)symbol(u->lib, "fmi3SetFloat64");
    u->do_step = (fmi3DoStepTYPE *)symbol(u->lib, "fmi3DoStep");
    u->terminate = (fmi3TerminateTYPE *)symbol(u->lib, "fmi3Terminate");
    u->free_instance = (fmi3FreeInstanceTYPE *)symbol(u->lib, "fmi3FreeInstance");
}

static void check(fmi3Status s, const char *what, double t) {
    if (s != fmi3OK) {
        fprintf(stderr, "%s at t = %g: status %d\n", what, t, (int)s);
        exit(2);
    }
}

static void transfer(const Unit *from, const Unit *to, const Links *l, double t) {
    fmi3Float64 v[MAX_VARS];
    check(from->get(from->c, l->src, l->n, v, l->n), "fmi3GetFloat64", t);
    check(to->set(to->c, l->dst, l->n, v, l->n), "fmi3SetFloat64", t);
}

static void step(const Unit *u, double t, double h, const char *what) {
    fmi3Boolean event = fmi3True, terminate = fmi3True, early = fmi3True;
    fmi3Float64 last = -1.0;
    check(u->do_step(u->c, t, h, fmi3True, &event, &terminate, &early, &last), what, t);
    if (event || terminate || early || last != t + h) {
        fprintf(stderr, "%s at t = %g: unexpected out-arguments\n", what, t);
        exit(2);
    }
}

static fmi3Instance instantiate(const Unit *u, const char *name, const char *token) {
    return u->instantiate(name, token, "", fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, (void *)name,
                          logger, NULL);
}

int main(int argc, char **argv) {
    if (argc != 10) {
        fprintf(stderr, "usage: %s PLANT.so TOKEN CONTROLLER.so TOKEN H T_STOP TO_CONTROLLER TO_PLANT RECORD\n",
                argv[0]);
        return 1;
    }
    Unit plant, controller;
    Links to_controller, to_plant, record;
    load(&plant, argv[1]);
    load(&controller, argv[3]);
    double h = atof(argv[5]), t_stop = atof(argv[6]);
    parse(&to_controller, argv[7], 1);
    parse(&to_plant, argv[8], 1);
    parse(&record, argv[9], 0);
    plant.c = instantiate(&plant, "plant", argv[2]);
    controller.c = instantiate(&controller, "controller", argv[4]);
    if (!plant.c || !controller.c) {
        fprintf(stderr, "fmi3InstantiateCoSimulation failed\n");
        return 2;
    }
    Unit *units[2] = {&plant, &controller};
    for (int i = 0; i < 2; i++)
        check(units[i]->enter_init(units[i]->c, fmi3False, 0.0, 0.0, fmi3False, 0.0), "fmi3EnterInitializationMode",
              0.0);
    check(plant.exit_init(plant.c), "fmi3ExitInitializationMode(plant)", 0.0);
    transfer(&plant, &controller, &to_controller, 0.0);
    check(controller.exit_init(controller.c), "fmi3ExitInitializationMode(controller)", 0.0);

    long n = (long)(t_stop / h + 0.5);
    fmi3Float64 row[MAX_VARS];
    for (long k = 0; k <= n; k++) {
        double t = (double)k * h;
        transfer(&plant, &controller, &to_controller, t);
        step(&controller, t, h, "fmi3DoStep(controller)");
        transfer(&controller, &plant, &to_plant, t);
        check(plant.get(plant.c, record.src, record.n, row, record.n), "fmi3GetFloat64(record)", t);
        printf("%.17g", t);
        for (size_t i = 0; i < record.n; i++) printf(",%.17g", row[i]);
        putchar('\n');
        if (k < n) step(&plant, t, h, "fmi3DoStep(plant)");
    }
    for (int i = 0; i < 2; i++) {
        check(units[i]->terminate(units[i]->c), "fmi3Terminate", t_stop);
        units[i]->free_instance(units[i]->c);
    }
    return 0;
}
