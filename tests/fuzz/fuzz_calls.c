/* libFuzzer harness for call sequences: the bytes are a program of FMI calls, in any order and
   state, with any arguments, on two instances of either interface of either standard (both
   adapters are linked in over the one core). Nothing may crash, leak or touch memory it does
   not own, and a state pointer an instance did not hand out must be refused (a master's bugs:
   another instance's state, a freed one, any address, fmusim 0.0.39's fmi2FreeFMUstate(c, state)). */

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"
#include "model_variables.h"

static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
    (void)e, (void)n, (void)s, (void)c, (void)m;
}

static const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};

static void logger3(fmi3InstanceEnvironment e, fmi3Status s, fmi3String c, fmi3String m) {
    (void)e, (void)s, (void)c, (void)m;
}

typedef struct {
    const uint8_t *data;
    size_t size;
} Program;

static uint8_t next_byte(Program *p) {
    if (!p->size) return 0;
    p->size--;
    return *p->data++;
}

static double next_double(Program *p) {
    double value = 0;
    uint8_t bytes[sizeof(value)];
    for (size_t i = 0; i < sizeof(bytes); i++) bytes[i] = next_byte(p);
    memcpy(&value, bytes, sizeof(value));
    return value;
}

/* Mostly sensible values so deep states are reached, sometimes arbitrary bit patterns. */
static double next_value(Program *p) {
    const uint8_t kind = next_byte(p);
    if (kind < 200) return (kind - 100) * 0.01;
    return next_double(p);
}

/* The FMI 3.0 counterpart of one operation of the program below. */
static void fmi3_operation(Program *p, int operation, fmi3Instance c, fmi3FMUState *state, double *time,
                           fmi3ValueReference vr[2]) {
    double values[2] = {0, 0}, x[2] = {0, 0};
    fmi3Int32 orders[2] = {1, 1};
    fmi3Boolean flags[5];
    fmi3Float64 last;
    switch (operation) {
        case 2: fmi3EnterInitializationMode(c, next_byte(p) & 1, next_value(p), 0, fmi3False, 0); *time = 0; break;
        case 3: fmi3EnterEventMode(c); break;
        case 4: fmi3ExitInitializationMode(c); break;
        case 5: values[0] = next_value(p); values[1] = next_value(p);
                fmi3SetFloat64(c, vr, next_byte(p) % 3, values, next_byte(p) % 3); break;
        case 6: fmi3GetFloat64(c, vr, next_byte(p) % 3, values, next_byte(p) % 3); break;
        case 7: {
            const double h = next_byte(p) % 4 == 0 ? next_double(p) : (next_byte(p) + 1) * 1e-3;
            if (fmi3DoStep(c, *time, h, fmi3True, &flags[0], &flags[1], &flags[2], &last) == fmi3OK) *time += h;
            break;
        }
        case 8: fmi3Terminate(c); break;
        case 9: fmi3Reset(c); *time = 0; break;
        case 10: if (!*state) fmi3GetFMUState(c, state); break;
        case 11: if (*state) fmi3SetFMUState(c, *state); break;
        case 12: x[0] = 1.0; fmi3GetAdjointDerivative(c, vr, 1, vr + 1, 1, x, 1, values, next_byte(p) % 3); break;
        case 13: orders[0] = next_byte(p) % 4; fmi3GetOutputDerivatives(c, vr, 1, orders, values, 1); break;
        case 14: x[0] = 1.0; fmi3GetDirectionalDerivative(c, vr, 1, vr + 1, 1, x, next_byte(p) % 3, values, 1); break;
        case 15: fmi3EnterContinuousTimeMode(c); fmi3SetTime(c, next_value(p)); break;
        case 16: x[0] = next_value(p); x[1] = next_value(p); fmi3SetContinuousStates(c, x, next_byte(p) % 4);
                 fmi3GetContinuousStateDerivatives(c, values, next_byte(p) % 4); break;
        case 17: fmi3UpdateDiscreteStates(c, &flags[0], &flags[1], &flags[2], &flags[3], &flags[4], &last); break;
    }
}

/* fmi2Status and fmi3Status share their values. */
#define ERROR 3
#define REQUIRE(condition) do { if (!(condition)) abort(); } while (0)

static int free_state(int standard, void *instance, void **state) {
    return standard == 3 ? (int)fmi3FreeFMUState(instance, state) : (int)fmi2FreeFMUstate(instance, state);
}

static int set_state(int standard, void *instance, void *state) {
    return standard == 3 ? (int)fmi3SetFMUState(instance, state) : (int)fmi2SetFMUstate(instance, state);
}

static int get_state(int standard, void *instance, void **state) {
    return standard == 3 ? (int)fmi3GetFMUState(instance, state) : (int)fmi2GetFMUstate(instance, state);
}

/* The states in play: states[s] came from instance owner[s]; stale is the address of a state
   that was freed, which no instance may take for its own (unless the allocator handed it out
   again to a state in states[]). */
typedef struct {
    void *states[2];
    int owner[2];
    void *stale;
} States;

static int live_state_of(const States *st, int i, const void *state) {
    for (int s = 0; s < 2; s++)
        if (st->states[s] == state && st->owner[s] == i) return 1;
    return 0;
}

/* Frees instance i: the other instance's states are refused, its own freed now or left to
   fmi*FreeInstance. */
static void free_instance(Program *p, void *instance, int standard, int i, States *st) {
    const int free_own = next_byte(p) & 1;
    for (int s = 0; s < 2; s++) {
        if (!st->states[s]) continue;
        if (st->owner[s] != i) {
            void *kept = st->states[s];
            REQUIRE(free_state(standard, instance, &st->states[s]) == ERROR && st->states[s] == kept);
            continue;
        }
        st->stale = st->states[s];
        if (free_own) REQUIRE(free_state(standard, instance, &st->states[s]) != ERROR);
        st->states[s] = NULL;
    }
    if (standard == 3) fmi3FreeInstance(instance);
    else fmi2FreeInstance(instance);
}

/* A master's bug with states on instance i, which must be refused with an error. */
static void foreign_state(Program *p, void *c, int standard, int i, int s, States *st) {
    void *state = st->states[s];
    switch (next_byte(p) % 4) {
        case 0: /* fmusim 0.0.39: the state where &state belongs */
            if (state && st->owner[s] == i) REQUIRE(free_state(standard, c, (void **)state) == ERROR);
            break;
        case 1: /* another instance's state */
            if (state && st->owner[s] != i) {
                REQUIRE(set_state(standard, c, state) == ERROR);
                REQUIRE(get_state(standard, c, &st->states[s]) == ERROR && st->states[s] == state);
                REQUIRE(free_state(standard, c, &st->states[s]) == ERROR && st->states[s] == state);
            }
            break;
        case 2: /* a freed state */
            state = st->stale;
            if (state && !live_state_of(st, i, state)) {
                REQUIRE(set_state(standard, c, state) == ERROR);
                REQUIRE(free_state(standard, c, &state) == ERROR && state == st->stale);
            }
            break;
        case 3: { /* any address */
            uintptr_t address = 0;
            for (size_t k = 0; k < sizeof(address); k++) address = address << 8 | next_byte(p);
            state = (void *)address;
            if (state && !live_state_of(st, i, state)) REQUIRE(set_state(standard, c, state) == ERROR);
            break;
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    Program p = {data, size};
    void *instances[2] = {NULL, NULL};
    int standard[2] = {2, 2};
    States st = {{NULL, NULL}, {-1, -1}, NULL};
    void **states = st.states;
    double time[2] = {0, 0};
    for (int count = 0; p.size && count < 256; count++) {
        const uint8_t op = next_byte(&p);
        const int i = op & 1, s = (op >> 1) & 1;
        fmi2Component c = instances[i];
        fmi2ValueReference vr[2] = {next_byte(&p) % (N_VARIABLES + 2), next_byte(&p) % (N_VARIABLES + 2)};
        double values[2] = {0, 0}, x[2] = {0, 0};
        fmi2Integer orders[2] = {1, 1};
        const int operation = (op >> 2) % 19;
        const void *had = states[s];
        if (c && operation == 18) {
            foreign_state(&p, c, standard[i], i, s, &st);
            continue;
        }
        if (c && standard[i] == 3 && operation > 1) {
            fmi3_operation(&p, operation, c, &states[s], &time[i], vr);
            if (!had && states[s]) st.owner[s] = i;
            continue;
        }
        switch (operation) {
            case 0:
                if (!c) {
                    const uint8_t kind = next_byte(&p), logging = next_byte(&p) & 1;
                    standard[i] = kind & 4 ? 3 : 2;
                    if (standard[i] == 2)
                        instances[i] = fmi2Instantiate("fuzz", kind % 3 ? fmi2CoSimulation : fmi2ModelExchange,
                                                       MODEL_GUID, "", &callbacks, fmi2False, logging);
                    else if (kind % 3)
                        instances[i] = fmi3InstantiateCoSimulation("fuzz", MODEL_GUID, "", fmi3False, logging,
                                                                   fmi3False, fmi3False, NULL, 0, NULL, logger3, NULL);
                    else
                        instances[i] = fmi3InstantiateModelExchange("fuzz", MODEL_GUID, "", fmi3False, logging,
                                                                    NULL, logger3);
                }
                break;
            case 1:
                if (c) {
                    free_instance(&p, c, standard[i], i, &st);
                    instances[i] = NULL;
                }
                break;
            case 2: fmi2SetupExperiment(c, next_byte(&p) & 1, next_value(&p), 0, fmi2False, 0); time[i] = 0; break;
            case 3: fmi2EnterInitializationMode(c); break;
            case 4: fmi2ExitInitializationMode(c); break;
            case 5: values[0] = next_value(&p); values[1] = next_value(&p);
                    fmi2SetReal(c, vr, next_byte(&p) % 3, values); break;
            case 6: fmi2GetReal(c, vr, next_byte(&p) % 3, values); break;
            case 7: {
                const double h = next_byte(&p) % 4 == 0 ? next_double(&p) : (next_byte(&p) + 1) * 1e-3;
                if (fmi2DoStep(c, time[i], h, fmi2True) == fmi2OK) time[i] += h;
                break;
            }
            case 8: fmi2Terminate(c); break;
            case 9: fmi2Reset(c); time[i] = 0; break;
            case 10: if (c && !states[s] && fmi2GetFMUstate(c, &states[s]) == fmi2OK) st.owner[s] = i; break;
            case 11: if (c && states[s]) fmi2SetFMUstate(c, states[s]); break;
            case 12: values[0] = next_value(&p); orders[0] = next_byte(&p) % 4;
                     fmi2SetRealInputDerivatives(c, vr, 1, orders, values); break;
            case 13: orders[0] = next_byte(&p) % 4; fmi2GetRealOutputDerivatives(c, vr, 1, orders, values); break;
            case 14: x[0] = 1.0; fmi2GetDirectionalDerivative(c, vr, 1, vr + 1, 1, x, values); break;
            case 15: fmi2EnterContinuousTimeMode(c); fmi2SetTime(c, next_value(&p)); break;
            case 16: x[0] = next_value(&p); x[1] = next_value(&p); fmi2SetContinuousStates(c, x, next_byte(&p) % 4);
                     fmi2GetDerivatives(c, values, next_byte(&p) % 4); break;
            case 17: {
                fmi2EventInfo info;
                fmi2NewDiscreteStates(c, &info);
                break;
            }
        }
    }
    for (int i = 0; i < 2; i++)
        if (instances[i]) free_instance(&p, instances[i], standard[i], i, &st);
    return 0;
}
