/* libFuzzer harness for call sequences: the bytes are a program of FMI calls, in any order and
   state, with any arguments, on two instances of either interface. Nothing may crash, leak or
   touch memory it does not own. */

#include <stdint.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model_variables.h"

static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
    (void)e, (void)n, (void)s, (void)c, (void)m;
}

static const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};

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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    Program p = {data, size};
    fmi2Component instances[2] = {NULL, NULL};
    fmi2FMUstate states[2] = {NULL, NULL};
    double time[2] = {0, 0};
    for (int count = 0; p.size && count < 256; count++) {
        const uint8_t op = next_byte(&p);
        const int i = op & 1, s = (op >> 1) & 1;
        fmi2Component c = instances[i];
        fmi2ValueReference vr[2] = {next_byte(&p) % (N_VARIABLES + 2), next_byte(&p) % (N_VARIABLES + 2)};
        double values[2] = {0, 0}, x[2] = {0, 0};
        fmi2Integer orders[2] = {1, 1};
        switch ((op >> 2) % 18) {
            case 0:
                if (!c) instances[i] = fmi2Instantiate("fuzz", next_byte(&p) % 3 ? fmi2CoSimulation : fmi2ModelExchange,
                                                       MODEL_GUID, "", &callbacks, fmi2False, next_byte(&p) & 1);
                break;
            case 1:
                if (c) {
                    if (states[0]) fmi2FreeFMUstate(c, &states[0]);
                    if (states[1]) fmi2FreeFMUstate(c, &states[1]);
                    fmi2FreeInstance(c);
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
    for (int i = 0; i < 2; i++) {
        if (!instances[i]) continue;
        for (int s = 0; s < 2; s++)
            if (states[s]) fmi2FreeFMUstate(instances[i], &states[s]);
        fmi2FreeInstance(instances[i]);
    }
    return 0;
}
