/* libFuzzer harness for call sequences: the bytes are a program of FMI calls, in any order and
   state, with any arguments, on two instances of either interface of either standard (both
   adapters are linked in over the one core). Nothing may crash, leak or touch memory it does
   not own. */

#include <stdint.h>
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

static void free_instance(void *instance, int standard, void *states[2]) {
    for (int s = 0; s < 2; s++) {
        if (!states[s]) continue;
        if (standard == 3) fmi3FreeFMUState(instance, &states[s]);
        else fmi2FreeFMUstate(instance, &states[s]);
    }
    if (standard == 3) fmi3FreeInstance(instance);
    else fmi2FreeInstance(instance);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    Program p = {data, size};
    void *instances[2] = {NULL, NULL};
    int standard[2] = {2, 2};
    void *states[2] = {NULL, NULL};
    double time[2] = {0, 0};
    for (int count = 0; p.size && count < 256; count++) {
        const uint8_t op = next_byte(&p);
        const int i = op & 1, s = (op >> 1) & 1;
        fmi2Component c = instances[i];
        fmi2ValueReference vr[2] = {next_byte(&p) % (N_VARIABLES + 2), next_byte(&p) % (N_VARIABLES + 2)};
        double values[2] = {0, 0}, x[2] = {0, 0};
        fmi2Integer orders[2] = {1, 1};
        const int operation = (op >> 2) % 18;
        if (c && standard[i] == 3 && operation > 1) {
            fmi3_operation(&p, operation, c, &states[s], &time[i], vr);
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
                    free_instance(c, standard[i], states);
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
            case 10: if (c && !states[s]) fmi2GetFMUstate(c, &states[s]); break;
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
        if (instances[i]) free_instance(instances[i], standard[i], states);
    return 0;
}
