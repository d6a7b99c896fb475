/* A minimal FMI 2.0 Co-Simulation master in C: plant + controller, Gauss-Seidel, the
 * timing of tailsim's ClosedLoop (python/tailsim/masters/system.py): at each
 * communication point t = k h the controller reads the plant's outputs and steps
 * (t, h), the plant reads the controller's outputs, the plant's outputs at t are
 * recorded, then the plant steps (t, h). Initialisation: the plant leaves
 * initialisation mode first, the controller after its linked inputs are set. Inputs not
 * linked (wind, reference offset) keep their start values (0).
 *
 * Built for the host and for aarch64 (tests/test_aarch64.py): the same source flies the
 * same units on both, so the records can be compared value for value.
 *
 * usage: master PLANT.so PLANT_GUID CONTROLLER.so CONTROLLER_GUID H T_STOP
 *               TO_CONTROLLER TO_PLANT RECORD
 *   TO_CONTROLLER: "p1:c1,p2:c2,..." plant output vr -> controller input vr (Reals)
 *   TO_PLANT:      "c1:p1,..."       controller output vr -> plant input vr (Reals)
 *   RECORD:        "p1,p2,..."       plant Real outputs written per row
 * Prints one CSV row per communication point: t, then the recorded values (%.17g).
 * Exit status 0 on success, 1 on a usage or load error, 2 on an FMI error status. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "master_common.h"

typedef struct {
    void *lib;
    fmi2Component c;
    fmi2InstantiateTYPE *instantiate;
    fmi2SetupExperimentTYPE *setup_experiment;
    fmi2EnterInitializationModeTYPE *enter_init;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2GetRealTYPE *get_real;
    fmi2SetRealTYPE *set_real;
    fmi2DoStepTYPE *do_step;
    fmi2TerminateTYPE *terminate;
    fmi2FreeInstanceTYPE *free_instance;
} Unit;


static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%s] %d %s: ", name, (int)status, category);
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static void load(Unit *u, const char *path) {
    u->lib = open_library(path);
    u->instantiate = (fmi2InstantiateTYPE *)symbol(u->lib, "fmi2Instantiate");
    u->setup_experiment = (fmi2SetupExperimentTYPE *)symbol(u->lib, "fmi2SetupExperiment");
    u->enter_init = (fmi2EnterInitializationModeTYPE *)symbol(u->lib, "fmi2EnterInitializationMode");
    u->exit_init = (fmi2ExitInitializationModeTYPE *)symbol(u->lib, "fmi2ExitInitializationMode");
    u->get_real = (fmi2GetRealTYPE *)symbol(u->lib, "fmi2GetReal");
    u->set_real = (fmi2SetRealTYPE *)symbol(u->lib, "fmi2SetReal");
    u->do_step = (fmi2DoStepTYPE *)symbol(u->lib, "fmi2DoStep");
    u->terminate = (fmi2TerminateTYPE *)symbol(u->lib, "fmi2Terminate");
    u->free_instance = (fmi2FreeInstanceTYPE *)symbol(u->lib, "fmi2FreeInstance");
}

static void check(fmi2Status s, const char *what, double t) {
    if (s != fmi2OK) {
        fprintf(stderr, "%s at t = %g: status %d\n", what, t, (int)s);
        exit(2);
    }
}

/* Copy the linked outputs of `from` to the inputs of `to`. */
static void transfer(const Unit *from, const Unit *to, const Links *l, double t) {
    fmi2Real v[MAX_VARS];
    check(from->get_real(from->c, l->src, l->n, v), "fmi2GetReal", t);
    check(to->set_real(to->c, l->dst, l->n, v), "fmi2SetReal", t);
}

int main(int argc, char **argv) {
    if (argc != 10) {
        fprintf(stderr,
                "usage: %s PLANT.so PLANT_GUID CONTROLLER.so CONTROLLER_GUID H T_STOP TO_CONTROLLER TO_PLANT "
                "RECORD\n",
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
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    plant.c = plant.instantiate("plant", fmi2CoSimulation, argv[2], "", &callbacks, fmi2False, fmi2False);
    controller.c =
        controller.instantiate("controller", fmi2CoSimulation, argv[4], "", &callbacks, fmi2False, fmi2False);
    if (!plant.c || !controller.c) {
        fprintf(stderr, "fmi2Instantiate failed\n");
        return 2;
    }
    Unit *units[2] = {&plant, &controller};
    for (int i = 0; i < 2; i++) {
        check(units[i]->setup_experiment(units[i]->c, fmi2False, 0.0, 0.0, fmi2False, 0.0), "fmi2SetupExperiment",
              0.0);
        check(units[i]->enter_init(units[i]->c), "fmi2EnterInitializationMode", 0.0);
    }
    check(plant.exit_init(plant.c), "fmi2ExitInitializationMode(plant)", 0.0);
    transfer(&plant, &controller, &to_controller, 0.0);
    check(controller.exit_init(controller.c), "fmi2ExitInitializationMode(controller)", 0.0);

    long n = (long)(t_stop / h + 0.5);
    fmi2Real row[MAX_VARS];
    for (long k = 0; k <= n; k++) {
        double t = (double)k * h;
        transfer(&plant, &controller, &to_controller, t);
        check(controller.do_step(controller.c, t, h, fmi2True), "fmi2DoStep(controller)", t);
        transfer(&controller, &plant, &to_plant, t);
        check(plant.get_real(plant.c, record.src, record.n, row), "fmi2GetReal(record)", t);
        printf("%.17g", t);
        for (size_t i = 0; i < record.n; i++) printf(",%.17g", row[i]);
        putchar('\n');
        if (k < n) check(plant.do_step(plant.c, t, h, fmi2True), "fmi2DoStep(plant)", t);
    }
    for (int i = 0; i < 2; i++) {
        check(units[i]->terminate(units[i]->c), "fmi2Terminate", t_stop);
        units[i]->free_instance(units[i]->c);
    }
    return 0;
}
