/* Drives the FMU's sources, linked in, through the bad calls and loads a master can inflict,
   so AddressSanitizer, UndefinedBehaviorSanitizer and valgrind watch every access.

   Both adapters are linked in, so the FMI 3.0 entry points get the same treatment.

   usage: driver bad-calls | bad-calls-fmi3 | foreign-states | instances N | threads N
                 | energy STEPS | churn N [MAX_GROWTH_KIB] | churn-fmi3 N
   Prints one line of figures per case; exits non-zero on the first failed expectation. */

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"
#include "model_variables.h"

static int messages_logged;
/* Only the single-threaded cases log, so one buffer serves. */
static char last_message[512];

static void logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                   fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)environment, (void)instance_name, (void)status, (void)category;
    snprintf(last_message, sizeof(last_message), "%s", message);
    __atomic_add_fetch(&messages_logged, 1, __ATOMIC_RELAXED);
}

static const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};

static void logger3(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                    fmi3String message) {
    (void)environment, (void)status, (void)category;
    snprintf(last_message, sizeof(last_message), "%s", message);
    __atomic_add_fetch(&messages_logged, 1, __ATOMIC_RELAXED);
}

#define EXPECT(condition)                                                                    \
    do {                                                                                     \
        if (!(condition)) {                                                                  \
            fprintf(stderr, "%s:%d: expected %s\n", __FILE__, __LINE__, #condition);         \
            exit(1);                                                                         \
        }                                                                                    \
    } while (0)

static fmi2Component ready(const char *name, double torque_start) {
    fmi2Component c = fmi2Instantiate(name, fmi2CoSimulation, MODEL_GUID, "", &callbacks, fmi2False, fmi2False);
    EXPECT(c != NULL);
    EXPECT(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK);
    EXPECT(fmi2EnterInitializationMode(c) == fmi2OK);
    const fmi2ValueReference torque = VR_TORQUE;
    EXPECT(fmi2SetReal(c, &torque, 1, &torque_start) == fmi2OK);
    EXPECT(fmi2ExitInitializationMode(c) == fmi2OK);
    return c;
}

static double theta_of(fmi2Component c) {
    const fmi2ValueReference theta_vr = VR_THETA;
    double theta = 0;
    EXPECT(fmi2GetReal(c, &theta_vr, 1, &theta) == fmi2OK);
    return theta;
}

/* theta after the 1 ms steps first..last-1 (from t = first ms) under a constant torque. */
static double run_steps(fmi2Component c, double torque, long first, long last) {
    const fmi2ValueReference torque_vr = VR_TORQUE;
    for (long k = first; k < last; k++) {
        EXPECT(fmi2SetReal(c, &torque_vr, 1, &torque) == fmi2OK);
        EXPECT(fmi2DoStep(c, k * 1e-3, 1e-3, fmi2True) == fmi2OK);
    }
    return theta_of(c);
}

/* theta after `steps` 1 ms steps under a constant torque. */
static double run(fmi2Component c, double torque, long steps) {
    return run_steps(c, torque, 0, steps);
}

/* 1 when the deserializer of one standard refuses the bytes and yields no state. */
typedef int (*Refuses)(void *instance, const unsigned char *bytes, size_t size);

static int deserialize_fmi2(void *instance, const unsigned char *bytes, size_t size) {
    fmi2FMUstate state = NULL;
    return fmi2DeSerializeFMUstate(instance, (const fmi2Byte *)bytes, size, &state) == fmi2Error && !state;
}

static int deserialize_fmi3(void *instance, const unsigned char *bytes, size_t size) {
    fmi3FMUState state = NULL;
    return fmi3DeserializeFMUState(instance, bytes, size, &state) == fmi3Error && !state;
}

/* Every truncation and every single-byte corruption of a serialized state must be refused;
   returns how many were. */
static int refuse_every_damaged_copy(void *instance, unsigned char *blob, size_t size, Refuses refuses) {
    for (size_t length = 0; length < size; length++) {
        unsigned char *truncated = malloc(length ? length : 1); /* exactly length bytes: ASan sees any overread */
        memcpy(truncated, blob, length);
        EXPECT(refuses(instance, truncated, length));
        free(truncated);
    }
    for (size_t i = 0; i < size; i++) {
        blob[i] ^= 0x5a;
        EXPECT(refuses(instance, blob, size));
        blob[i] ^= 0x5a;
    }
    return (int)(2 * size);
}

static void bad_calls(void) {
    const fmi2ValueReference theta = VR_THETA, mass = VR_MASS, unknown = 1000;
    double value = NAN, one = 1.0;
    int refused = 0;
#define REFUSED(call) do { EXPECT((call) == fmi2Error); refused++; } while (0)
    EXPECT(fmi2Instantiate("x", fmi2CoSimulation, MODEL_GUID, "", NULL, 0, 0) == NULL);
    fmi2CallbackFunctions no_logger = {NULL, NULL, NULL, NULL, NULL};
    EXPECT(fmi2Instantiate("x", fmi2CoSimulation, MODEL_GUID, "", &no_logger, 0, 0) == NULL);
    EXPECT(fmi2Instantiate(NULL, fmi2CoSimulation, MODEL_GUID, "", &callbacks, 0, 0) == NULL);
    EXPECT(fmi2Instantiate("x", fmi2CoSimulation, "{wrong}", "", &callbacks, 0, 0) == NULL);
    EXPECT(fmi2Instantiate("x", (fmi2Type)42, MODEL_GUID, "", &callbacks, 0, 0) == NULL);
    fmi2FreeInstance(NULL);
    REFUSED(fmi2DoStep(NULL, 0, 1e-3, 0));
    REFUSED(fmi2GetReal(NULL, &theta, 1, &value));

    fmi2Component c = fmi2Instantiate("bad", fmi2CoSimulation, MODEL_GUID, "", &callbacks, 0, 0);
    REFUSED(fmi2DoStep(c, 0, 1e-3, 0));
    REFUSED(fmi2GetReal(c, &theta, 1, &value));
    REFUSED(fmi2SetReal(c, &theta, 1, &value));           /* NaN start value */
    REFUSED(fmi2SetReal(c, &unknown, 1, &one));
    REFUSED(fmi2SetReal(c, NULL, 1, &one));
    REFUSED(fmi2SetReal(c, &theta, 1, NULL));
    EXPECT(fmi2SetReal(c, NULL, 0, NULL) == fmi2OK);      /* nothing to set is fine */
    double zero = 0;
    EXPECT(fmi2SetReal(c, &mass, 1, &zero) == fmi2OK);
    EXPECT(fmi2EnterInitializationMode(c) == fmi2OK);
    REFUSED(fmi2ExitInitializationMode(c));               /* mass 0 */
    EXPECT(fmi2SetReal(c, &mass, 1, &one) == fmi2OK);
    EXPECT(fmi2ExitInitializationMode(c) == fmi2OK);
    REFUSED(fmi2SetReal(c, &mass, 1, &one));              /* fixed after initialization */
    REFUSED(fmi2DoStep(c, 0, -1, 0));
    REFUSED(fmi2DoStep(c, 0, NAN, 0));
    REFUSED(fmi2DoStep(c, 5, 1e-3, 0));
    REFUSED(fmi2GetFMUstate(c, NULL));
    REFUSED(fmi2SetFMUstate(c, NULL));
    REFUSED(fmi2GetDirectionalDerivative(c, &theta, 1, &mass, 1, &one, &value));
    REFUSED(fmi2SetContinuousStates(c, &one, 1));
    REFUSED(fmi2CancelStep(c));

    /* Serialized states: every truncation, and every single-byte corruption, refused. */
    fmi2FMUstate state = NULL, restored = NULL;
    size_t size = 0;
    EXPECT(fmi2DoStep(c, 0, 1e-3, 0) == fmi2OK);
    EXPECT(fmi2GetFMUstate(c, &state) == fmi2OK);
    EXPECT(fmi2SerializedFMUstateSize(c, state, &size) == fmi2OK);
    fmi2Byte *blob = malloc(size);
    EXPECT(fmi2SerializeFMUstate(c, state, blob, size) == fmi2OK);
    REFUSED(fmi2SerializeFMUstate(c, state, blob, size - 1));
    refused += refuse_every_damaged_copy(c, (unsigned char *)blob, size, deserialize_fmi2);
    EXPECT(fmi2DeSerializeFMUstate(c, blob, size, &restored) == fmi2OK);
    EXPECT(fmi2SetFMUstate(c, restored) == fmi2OK);
    EXPECT(fmi2FreeFMUstate(c, &restored) == fmi2OK && restored == NULL);
    EXPECT(fmi2FreeFMUstate(c, &state) == fmi2OK);
    free(blob);
    EXPECT(fmi2DoStep(c, 1e-3, 1e-3, 0) == fmi2OK);       /* still usable after all that */
    fmi2FreeInstance(c);
    printf("bad-calls: %d refused calls, %d messages logged, %zu truncations and %zu corruptions of a "
           "%zu-byte state refused\n", refused, messages_logged, size, size, size);
#undef REFUSED
}

static fmi3Instance ready3(const char *name, int co_simulation) {
    fmi3Instance c = co_simulation
        ? fmi3InstantiateCoSimulation(name, MODEL_GUID, "", fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                                      NULL, logger3, NULL)
        : fmi3InstantiateModelExchange(name, MODEL_GUID, "", fmi3False, fmi3False, NULL, logger3);
    EXPECT(c != NULL);
    EXPECT(fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK);
    EXPECT(fmi3ExitInitializationMode(c) == fmi3OK);
    return c;
}

/* The FMI 3.0 entry points: refused calls, every truncation and single-byte corruption of a
   serialized state, and the same numbers as FMI 2.0 for the same held torque. */
static void bad_calls_fmi3(void) {
    const fmi3ValueReference theta = VR_THETA, mass = VR_MASS, torque_vr = VR_TORQUE, time_vr = N_VALUE_REFERENCES;
    double value = NAN, one = 1.0, x[2] = {0, 0};
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    int refused = 0;
#define REFUSED(call) do { EXPECT((call) == fmi3Error); refused++; } while (0)
    EXPECT(fmi3InstantiateCoSimulation("x", MODEL_GUID, "", 0, 0, 0, 0, NULL, 0, NULL, NULL, NULL) == NULL);
    EXPECT(fmi3InstantiateModelExchange(NULL, MODEL_GUID, "", 0, 0, NULL, logger3) == NULL);
    EXPECT(fmi3InstantiateModelExchange("x", "{wrong}", "", 0, 0, NULL, logger3) == NULL);
    EXPECT(fmi3InstantiateScheduledExecution("x", MODEL_GUID, "", 0, 0, NULL, logger3, NULL, NULL, NULL) == NULL);
    fmi3FreeInstance(NULL);
    REFUSED(fmi3DoStep(NULL, 0, 1e-3, fmi3True, &event, &terminate, &early, &last));

    fmi3Instance c = fmi3InstantiateCoSimulation("bad", MODEL_GUID, "", 0, 0, 0, 0, NULL, 0, NULL, logger3, NULL);
    REFUSED(fmi3DoStep(c, 0, 1e-3, fmi3True, &event, &terminate, &early, &last));
    REFUSED(fmi3SetFloat64(c, &theta, 1, &value, 1));        /* NaN start value */
    REFUSED(fmi3SetFloat64(c, &theta, 1, &one, 2));          /* nValues */
    REFUSED(fmi3SetFloat64(c, NULL, 1, &one, 1));
    REFUSED(fmi3SetFloat64(c, &time_vr, 1, &one, 1));
    EXPECT(fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK);
    EXPECT(fmi3ExitInitializationMode(c) == fmi3OK);
    REFUSED(fmi3SetFloat64(c, &mass, 1, &one, 1));           /* fixed after initialization */
    REFUSED(fmi3DoStep(c, 0, -1, fmi3True, &event, &terminate, &early, &last));
    REFUSED(fmi3DoStep(c, 0, 1e-3, fmi3True, NULL, &terminate, &early, &last));
    REFUSED(fmi3GetFMUState(c, NULL));
    REFUSED(fmi3SetFMUState(c, NULL));
    REFUSED(fmi3GetDirectionalDerivative(c, &theta, 1, &mass, 1, &one, 1, &value, 1));
    REFUSED(fmi3GetAdjointDerivative(c, &theta, 1, &theta, 1, &one, 1, NULL, 1));
    REFUSED(fmi3SetContinuousStates(c, x, 2));
    REFUSED(fmi3EnterConfigurationMode(c));
    REFUSED(fmi3GetClock(c, &theta, 1, NULL));
    REFUSED(fmi3EnterStepMode(c));
    REFUSED(fmi3UpdateDiscreteStates(c, NULL, NULL, NULL, NULL, NULL, NULL));

    fmi3FMUState state = NULL, restored = NULL;
    size_t size = 0;
    EXPECT(fmi3DoStep(c, 0, 1e-3, fmi3True, &event, &terminate, &early, &last) == fmi3OK && last == 1e-3);
    EXPECT(fmi3GetFMUState(c, &state) == fmi3OK);
    EXPECT(fmi3SerializedFMUStateSize(c, state, &size) == fmi3OK);
    fmi3Byte *blob = malloc(size);
    EXPECT(fmi3SerializeFMUState(c, state, blob, size) == fmi3OK);
    refused += refuse_every_damaged_copy(c, blob, size, deserialize_fmi3);
    EXPECT(fmi3DeserializeFMUState(c, blob, size, &restored) == fmi3OK);
    EXPECT(fmi3SetFMUState(c, restored) == fmi3OK);
    EXPECT(fmi3FreeFMUState(c, &restored) == fmi3OK && restored == NULL);
    EXPECT(fmi3FreeFMUState(c, &state) == fmi3OK);
    free(blob);
    fmi3FreeInstance(c);

    /* The same held torque gives FMI 2.0's numbers to the last bit. */
    fmi3Instance three = ready3("fmi3", 1);
    fmi2Component two = ready("fmi2", 0.0);
    const double torque = 20.0;
    double theta3, theta2;
    for (long k = 0; k < 3000; k++) {
        EXPECT(fmi3SetFloat64(three, &torque_vr, 1, &torque, 1) == fmi3OK);
        EXPECT(fmi3DoStep(three, k * 1e-3, 1e-3, fmi3True, &event, &terminate, &early, &last) == fmi3OK);
    }
    EXPECT(fmi3GetFloat64(three, &theta, 1, &theta3, 1) == fmi3OK);
    theta2 = run(two, torque, 3000);
    EXPECT(theta3 == theta2);
    fmi3FreeInstance(three);
    fmi2FreeInstance(two);
    printf("bad-calls-fmi3: %d refused calls, %zu truncations and %zu corruptions of a %zu-byte state "
           "refused, theta(3 s) equal to FMI 2.0's\n", refused, size, size, size);
#undef REFUSED
}

/* 1 when the last message logged contains text. */
static int logged(const char *text) {
    return strstr(last_message, text) != NULL;
}

#define FOREIGN "not a state this instance handed out"

/* A master's bugs with FMU states, each refused with an error and a message before the pointer
   is read; the instance steps on to the numbers of an instance that never saw them. */
static void foreign_states(void) {
    const double torque = 20.0;
    double not_a_state[64] = {0};
    int refused = 0;
#define REFUSED(call, text) do { last_message[0] = 0; EXPECT((call) == fmi2Error && logged(text)); refused++; } \
                            while (0)
    fmi2Component c = ready("master with bugs", 0.0), untouched = ready("untouched", 0.0);
    fmi2Component other = ready("other", 0.0);
    run(c, torque, 500);
    fmi2FMUstate state = NULL, other_state = NULL, stale, fake = not_a_state;
    EXPECT(fmi2GetFMUstate(c, &state) == fmi2OK && state != NULL);
    EXPECT(fmi2GetFMUstate(other, &other_state) == fmi2OK);

    /* fmusim 0.0.39's call: the state where &state belongs. */
    REFUSED(fmi2FreeFMUstate(c, state), "is a state itself");
    REFUSED(fmi2SetFMUstate(c, not_a_state), FOREIGN);
    REFUSED(fmi2FreeFMUstate(c, &fake), FOREIGN);
    EXPECT(fake == not_a_state);                          /* left as it was */
    REFUSED(fmi2GetFMUstate(c, &fake), FOREIGN);          /* not a state to overwrite */
    REFUSED(fmi2SetFMUstate(c, other_state), FOREIGN);    /* another instance's */
    REFUSED(fmi2FreeFMUstate(c, &other_state), FOREIGN);
    EXPECT(other_state != NULL);
    size_t size = 0;
    fmi2Byte blob[1024];
    REFUSED(fmi2SerializedFMUstateSize(c, other_state, &size), FOREIGN);
    REFUSED(fmi2SerializeFMUstate(c, not_a_state, blob, sizeof(blob)), FOREIGN);
    fmi2FMUstate none = NULL;
    EXPECT(fmi2FreeFMUstate(c, &none) == fmi2OK);         /* freeing NULL is ignored */

    /* The state survived the bad free: it still restores, and serializes. */
    const double theta_500 = theta_of(c);
    run_steps(c, torque, 500, 700);
    EXPECT(fmi2SetFMUstate(c, state) == fmi2OK && theta_of(c) == theta_500);
    EXPECT(fmi2SerializedFMUstateSize(c, state, &size) == fmi2OK && size <= sizeof(blob));
    EXPECT(fmi2SerializeFMUstate(c, state, blob, size) == fmi2OK);
    stale = state;
    EXPECT(fmi2FreeFMUstate(c, &state) == fmi2OK && state == NULL);
    REFUSED(fmi2SetFMUstate(c, stale), FOREIGN);          /* freed already */
    REFUSED(fmi2FreeFMUstate(c, &stale), FOREIGN);        /* a double free */

    const double theta = run_steps(c, torque, 500, 3000), expected = run(untouched, torque, 3000);
    EXPECT(theta == expected);

    /* FMI 3.0: the same core behind the other adapter. */
    fmi3Instance c3 = ready3("master with bugs 3", 1);
    fmi3FMUState state3 = NULL;
    EXPECT(fmi3GetFMUState(c3, &state3) == fmi3OK);
#undef REFUSED
#define REFUSED(call, text) do { last_message[0] = 0; EXPECT((call) == fmi3Error && logged(text)); refused++; } \
                            while (0)
    REFUSED(fmi3FreeFMUState(c3, state3), "is a state itself");
    REFUSED(fmi3SetFMUState(c3, not_a_state), FOREIGN);
    REFUSED(fmi3SetFMUState(c3, other_state), FOREIGN);   /* an FMI 2.0 instance's */
    REFUSED(fmi3SerializeFMUState(c3, not_a_state, (fmi3Byte *)blob, sizeof(blob)), FOREIGN);
    EXPECT(fmi3SetFMUState(c3, state3) == fmi3OK);
    EXPECT(fmi3FreeFMUState(c3, &state3) == fmi3OK && state3 == NULL);
#undef REFUSED

    /* other_state is left to fmi2FreeInstance, which frees what the master did not. */
    fmi3FreeInstance(c3);
    fmi2FreeInstance(other);
    fmi2FreeInstance(untouched);
    fmi2FreeInstance(c);
    printf("foreign-states: %d foreign state pointers refused, theta(3 s) = %.17g rad equal to an "
           "untouched instance's\n", refused, theta);
}

static void churn_fmi3(long n) {
    for (long i = 0; i < n; i++) {
        fmi3Instance c = ready3("churn", i % 2);
        fmi3FMUState state = NULL;
        if (i % 2) {
            fmi3Boolean event, terminate, early;
            fmi3Float64 last;
            EXPECT(fmi3DoStep(c, 0, 1e-3, fmi3True, &event, &terminate, &early, &last) == fmi3OK);
        }
        EXPECT(fmi3GetFMUState(c, &state) == fmi3OK && fmi3FreeFMUState(c, &state) == fmi3OK);
        fmi3FreeInstance(c);
    }
    printf("churn-fmi3: %ld instantiate/free cycles of both interfaces\n", n);
}

static void instances(long n) {
    fmi2Component *all = malloc(n * sizeof(*all));
    char name[32];
    for (long i = 0; i < n; i++) {
        snprintf(name, sizeof(name), "pendulum %ld", i);
        all[i] = ready(name, 0.0);
    }
    /* All live at once, each with its own torque, stepped in turn. */
    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    for (long k = 0; k < 100; k++) {
        for (long i = 0; i < n; i++) {
            const double torque = (double)(i % 50);
            EXPECT(fmi2SetReal(all[i], &torque_vr, 1, &torque) == fmi2OK);
            EXPECT(fmi2DoStep(all[i], k * 1e-3, 1e-3, fmi2True) == fmi2OK);
        }
    }
    for (long i = 0; i < n; i++) {
        double theta, alone;
        EXPECT(fmi2GetReal(all[i], &theta_vr, 1, &theta) == fmi2OK);
        if (i < 50) {
            fmi2Component single = ready("alone", 0.0);
            alone = run(single, (double)i, 100);
            fmi2FreeInstance(single);
            EXPECT(theta == alone);
        }
        fmi2FreeInstance(all[i]);
    }
    free(all);
    printf("instances: %ld live at once, each equal to the same run alone\n", n);
}

typedef struct {
    double torque;
    double theta;
} ThreadJob;

static void *thread_main(void *argument) {
    ThreadJob *job = argument;
    fmi2Component c = ready("thread", 0.0);
    job->theta = run(c, job->torque, 3000);
    fmi2FreeInstance(c);
    return NULL;
}

static void threads(int n) {
    pthread_t *ids = malloc(n * sizeof(*ids));
    ThreadJob *jobs = calloc(n, sizeof(*jobs));
    for (int i = 0; i < n; i++) {
        jobs[i].torque = 5.0 * (i + 1);
        EXPECT(pthread_create(&ids[i], NULL, thread_main, &jobs[i]) == 0);
    }
    for (int i = 0; i < n; i++) EXPECT(pthread_join(ids[i], NULL) == 0);
    for (int i = 0; i < n; i++) {
        fmi2Component c = ready("one thread", 0.0);
        EXPECT(run(c, jobs[i].torque, 3000) == jobs[i].theta);
        fmi2FreeInstance(c);
    }
    printf("threads: %d threads, each instance's theta(3 s) equal to the single-thread run\n", n);
    free(ids);
    free(jobs);
}

/* Released at 1 rad with no torque and no damping, the pendulum must keep its energy. */
static void energy(long steps) {
    fmi2Component c = fmi2Instantiate("energy", fmi2CoSimulation, MODEL_GUID, "", &callbacks, 0, 0);
    const fmi2ValueReference theta_vr = VR_THETA, omega_vr = VR_OMEGA;
    const double theta0 = 1.0;
    EXPECT(fmi2SetReal(c, &theta_vr, 1, &theta0) == fmi2OK);
    EXPECT(fmi2SetupExperiment(c, 0, 0, 0, 0, 0) == fmi2OK);
    EXPECT(fmi2EnterInitializationMode(c) == fmi2OK);
    EXPECT(fmi2ExitInitializationMode(c) == fmi2OK);
    const double mass = model_variables[VR_MASS].start, length = model_variables[VR_LENGTH].start;
    const double inertia = model_variables[VR_INERTIA].start + mass * length * length;
    const double weight_moment = mass * model_variables[VR_GRAVITY].start * length;
    const double energy0 = weight_moment * (1 - cos(theta0));
    double worst = 0, theta, omega;
    for (long k = 0; k < steps; k++) {
        EXPECT(fmi2DoStep(c, k * 1e-3, 1e-3, fmi2True) == fmi2OK);
        if (k % 1000 == 999 || k == steps - 1) {
            EXPECT(fmi2GetReal(c, &theta_vr, 1, &theta) == fmi2OK);
            EXPECT(fmi2GetReal(c, &omega_vr, 1, &omega) == fmi2OK);
            const double drift = fabs(0.5 * inertia * omega * omega + weight_moment * (1 - cos(theta)) - energy0) / energy0;
            if (drift > worst) worst = drift;
        }
    }
    fmi2FreeInstance(c);
    /* The default tolerance allows 1e-10 per internal step; 1 ms steps are far inside it. */
    printf("energy: %ld steps of 1 ms (%.0f s), worst relative energy drift %.3e\n", steps, steps * 1e-3, worst);
    EXPECT(worst < 1e-6);
}

static long resident_pages(void) {
    long size = 0, resident = 0;
    FILE *statm = fopen("/proc/self/statm", "r");
    if (statm) {
        EXPECT(fscanf(statm, "%ld %ld", &size, &resident) == 2);
        fclose(statm);
    }
    return resident;
}

static void churn(long n, long max_growth_kib) {
    long after_warmup = 0;
    for (long i = 0; i < n; i++) {
        fmi2Component c = ready("churn", 1.0);
        EXPECT(fmi2DoStep(c, 0, 1e-3, fmi2True) == fmi2OK);
        fmi2FMUstate state = NULL;
        EXPECT(fmi2GetFMUstate(c, &state) == fmi2OK && fmi2FreeFMUstate(c, &state) == fmi2OK);
        fmi2FreeInstance(c);
        if (i == 999) after_warmup = resident_pages();
    }
#ifdef __SANITIZE_ADDRESS__
    /* AddressSanitizer keeps freed memory in quarantine, so resident size says nothing here; its
       LeakSanitizer checks for leaks at exit instead. */
    (void)after_warmup, (void)max_growth_kib;
    printf("churn: %ld instantiate/step/free cycles (leaks: LeakSanitizer at exit)\n", n);
#else
    const long growth_kib = (resident_pages() - after_warmup) * sysconf(_SC_PAGESIZE) / 1024;
    printf("churn: %ld instantiate/step/free cycles, resident memory grew %ld KiB after the first 1000\n",
           n, growth_kib);
    /* Only meaningful natively: valgrind's allocator grows on its own. */
    if (max_growth_kib > 0) EXPECT(growth_kib <= max_growth_kib);
#endif
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s bad-calls | bad-calls-fmi3 | foreign-states | instances N | threads N "
                "| energy STEPS | churn N [MAX_GROWTH_KIB] | churn-fmi3 N\n", argv[0]);
        return 2;
    }
    const long n = argc > 2 ? atol(argv[2]) : 0;
    if (!strcmp(argv[1], "bad-calls")) bad_calls();
    else if (!strcmp(argv[1], "bad-calls-fmi3")) bad_calls_fmi3();
    else if (!strcmp(argv[1], "foreign-states")) foreign_states();
    else if (!strcmp(argv[1], "churn-fmi3")) churn_fmi3(n);
    else if (!strcmp(argv[1], "instances")) instances(n);
    else if (!strcmp(argv[1], "threads")) threads((int)n);
    else if (!strcmp(argv[1], "energy")) energy(n);
    else if (!strcmp(argv[1], "churn")) churn(n, argc > 3 ? atol(argv[3]) : 0);
    else return 2;
    return 0;
}
