#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"
#include "integrator.h"

/* A master's time arithmetic (t += h against t = n*h) may differ in the last bits from ours. */
#define TIME_MATCH_TOLERANCE 1e-9

static const char *const category_names[] = {"logStatusWarning", "logStatusDiscard",
                                             "logStatusError", "logAll", "logCalls"};
#define N_CATEGORIES (sizeof(category_names) / sizeof(category_names[0]))

void instance_log(const Instance *instance, Status status, LogCategory category,
                  const char *format, ...) {
    /* Room for a whole record line. */
    char message[RECORD_LINE_SIZE];
    va_list args;
    if (category >= LOG_ALL && !(instance->log_categories & category)) return;
    va_start(args, format);
    vsnprintf(message, sizeof(message), format, args);
    va_end(args);
    /* The category index is the bit's position. */
    size_t index = 0;
    while ((1u << index) != (unsigned)category) index++;
    /* Passed as the format itself, because some masters (fmpy among them) print the format and
       drop the arguments; so no '%' may reach a master that formats it. A master's strings come
       escaped (escape_text); this catches any that would not, and any control character, which
       could start a line of its own in the master's log. */
    for (char *c = message; *c; c++) {
        if (*c == '%') *c = '#';
        if ((unsigned char)*c < 0x20) *c = '?';
    }
    instance->logger.forward(instance->logger.master_logger, instance->logger.environment,
                             instance->name, status, category_names[index], message);
}

Status instance_error(const Instance *instance, const char *function, const char *format, ...) {
    char message[448];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof(message), format, args);
    va_end(args);
    instance_log(instance, STATUS_ERROR, LOG_STATUS_ERROR, "%s: %s", function, message);
    return STATUS_ERROR;
}

static const char *const status_names[] = {"OK", "Warning", "Discard", "Error", "Fatal"};

void instance_record_call(const Instance *instance, const char *function, double time_before,
                          Status status, const char *format, ...) {
    char arguments[RECORD_ARGUMENTS_SIZE];
    va_list args;
    va_start(args, format);
    vsnprintf(arguments, sizeof(arguments), format, args);
    va_end(args);
    /* Escaped, so that no name a master gives can end the quotes or the line: every line of a
       record starts with the marker (docs/calls.md says how the judge reads it back). */
    char name[ESCAPED_SIZE(MAX_INSTANCE_NAME)];
    escape_text(name, sizeof(name), instance->name);
    char line[RECORD_LINE_SIZE];
    snprintf(line, sizeof(line), CALL_RECORD_MARKER " instance=\"%s\" %s(%s) time=%.17g->%.17g status=%s",
             name, function, arguments, time_before, instance->data.time, status_names[status]);
    if (instance->record_file) record_file_append(instance->record_file, line);
    instance_log(instance, STATUS_OK, LOG_CALLS, "%s", line);
}

#ifdef VR_CALLRECORDFILE
/* Closes the record file there is, and opens the one `name` names (none when empty). */
static Status record_to_file(Instance *instance, const char *function, const char *name) {
    if (instance->record_file) record_file_close(instance->record_file);
    instance->record_file = NULL;
    instance->log_categories &= ~RECORD_TO_FILE;
    strcpy(instance->record_file_name, name);
    if (!name[0]) return STATUS_OK;
    char why[128];
    instance->record_file = record_file_open(name, CALL_RECORD_MARKER, why, sizeof(why));
    if (!instance->record_file) {
        char escaped[ESCAPED_SIZE(MAX_RECORD_FILE_NAME)];
        instance_log(instance, STATUS_WARNING, LOG_STATUS_WARNING,
                     "%s: callRecordFile \"%s\" %s: the FMU writes no record file (" RECORD_FILE_ADVICE ")",
                     function, escape_text(escaped, sizeof(escaped), name), why);
        return STATUS_WARNING;
    }
    instance->log_categories |= RECORD_TO_FILE;
    return STATUS_OK;
}
#endif

Status instance_set_string(Instance *instance, const char *function, const unsigned int vr[], size_t n,
                           const char *const value[]) {
    Status status = STATUS_OK;
    (void)value; /* a model without String parameters refuses every one */
    for (size_t i = 0; i < n; i++) {
#ifdef VR_CALLRECORDFILE
        if (vr[i] != VR_CALLRECORDFILE)
#endif
            return instance_error(instance, function, "vr %u: no String variable has this value "
                                  "reference", vr[i]);
#ifdef VR_CALLRECORDFILE
        if (!value[i])
            return instance_error(instance, function, "callRecordFile is NULL: pass \"\" for no "
                                  "record file");
        if (strlen(value[i]) >= MAX_RECORD_FILE_NAME)
            return instance_error(instance, function, "callRecordFile is %lu bytes long: at most %d",
                                  (unsigned long)strlen(value[i]), MAX_RECORD_FILE_NAME - 1);
        if (!(instance->data.machine_state & (STATE_INSTANTIATED | STATE_INITIALIZATION_MODE)))
            return instance_error(instance, function, "callRecordFile is a fixed parameter: set it "
                                  "before initialization ends");
        if (record_to_file(instance, function, value[i]) == STATUS_WARNING) status = STATUS_WARNING;
#endif
    }
    return status;
}

Status instance_get_string(Instance *instance, const char *function, const unsigned int vr[], size_t n,
                           const char *value[]) {
    (void)value; /* a model without String parameters refuses every one */
    for (size_t i = 0; i < n; i++) {
#ifdef VR_CALLRECORDFILE
        if (vr[i] == VR_CALLRECORDFILE) {
            value[i] = instance->record_file_name;
            continue;
        }
#endif
        return instance_error(instance, function, "vr %u: no String variable has this value reference",
                              vr[i]);
    }
    return STATUS_OK;
}

void instance_record_values(const Instance *instance, const char *function, double time_before,
                            Status status, const unsigned int vr[], const int order[], size_t n,
                            const double value[]) {
    char arguments[RECORD_ARGUMENTS_SIZE];
    size_t used = 0;
    arguments[0] = '\0';
    for (size_t i = 0; i < n && used < sizeof(arguments); i++) {
        const char *separator = i ? ", " : "";
        int written;
        if (vr && vr[i] >= N_VARIABLES)
            written = snprintf(arguments + used, sizeof(arguments) - used, "%svr%u=%.17g",
                               separator, vr[i], value[i]);
        else if (vr && order)
            written = snprintf(arguments + used, sizeof(arguments) - used, "%sder(%s,%d)=%.17g",
                               separator, model_variables[vr[i]].name, order[i], value[i]);
        else if (vr)
            written = snprintf(arguments + used, sizeof(arguments) - used, "%s%s=%.17g", separator,
                               model_variables[vr[i]].name, value[i]);
        else
            written = snprintf(arguments + used, sizeof(arguments) - used, "%sx[%lu]=%.17g",
                               separator, (unsigned long)i, value[i]);
        if (written < 0) break;
        used += (size_t)written;
    }
    instance_record_call(instance, function, time_before, status, "%s", arguments);
}

static const char *state_name(int state) {
    switch (state) {
        case STATE_INSTANTIATED: return "instantiated";
        case STATE_INITIALIZATION_MODE: return "initialization mode";
        case STATE_STEP_COMPLETE: return "step complete";
        case STATE_STEP_FAILED: return "step failed";
        case STATE_TERMINATED: return "terminated";
        case STATE_EVENT_MODE: return "event mode";
        case STATE_CONTINUOUS_TIME_MODE: return "continuous-time mode";
        default: return "unknown";
    }
}

int instance_illegal_call(const Instance *instance, int mask, const char *function) {
    const int co_simulation = instance->type == INTERFACE_CO_SIMULATION;
    if (mask & (co_simulation ? MODEL_EXCHANGE_ONLY : CO_SIMULATION_ONLY)) {
        instance_error(instance, function, "illegal call: a %s function, and this instance is for %s",
                       co_simulation ? "model-exchange" : "co-simulation",
                       co_simulation ? "co-simulation" : "model exchange");
        if (instance_recording(instance))
            instance_record_call(instance, function, instance->data.time, STATUS_ERROR,
                                 "refused: a function of the other interface");
        return 0;
    }
    instance_error(instance, function, "illegal call sequence: not allowed in state '%s'",
                   state_name(instance->data.machine_state));
    if (instance_recording(instance))
        instance_record_call(instance, function, instance->data.time, STATUS_ERROR,
                             "refused in state '%s'", state_name(instance->data.machine_state));
    return 0;
}

int instance_null_argument(const Instance *instance, const char *function, const char *argument,
                           const void *pointer) {
    if (pointer) return 0;
    instance_error(instance, function, "argument %s must not be NULL", argument);
    return 1;
}

Instance *instance_refuse(const char *function, const char *name, const Logger *logger,
                          const char *format, ...) {
    if (!logger || !logger->master_logger) return NULL;
    /* No instance yet: a stand-in carries the master's logger and the name for the message. */
    Instance probe;
    memset(&probe, 0, sizeof(probe));
    probe.logger = *logger;
    snprintf(probe.name, sizeof(probe.name), "%s", name ? name : "?");
    char message[448];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof(message), format, args);
    va_end(args);
    instance_error(&probe, function, "%s", message);
    return NULL;
}

Instance *instance_create(const char *function, const char *name, const char *token_argument,
                          const char *token, InterfaceType type, const Logger *logger, int logging_on) {
    /* Without a logger there is nobody to tell why we refuse: both standards require one. */
    if (!logger || !logger->master_logger) return NULL;
    if (!name || !name[0])
        return instance_refuse(function, name, logger, "instanceName must be a non-empty string");
    if (!token || strcmp(token, MODEL_GUID) != 0) {
        char escaped[96];
        return instance_refuse(function, name, logger,
                               "%s %s does not match this FMU's %s (was the model description "
                               "taken from another FMU?)", token_argument,
                               token ? escape_text(escaped, sizeof(escaped), token) : "NULL", MODEL_GUID);
    }

    Instance *instance = calloc(1, sizeof(Instance));
    if (!instance)
        return instance_refuse(function, name, logger, "out of memory");
    instance->logger = *logger;
    snprintf(instance->name, sizeof(instance->name), "%s", name);
    instance->type = type;
    instance->log_categories = logging_on ? (LOG_STATUS_WARNING | LOG_STATUS_DISCARD
                                             | LOG_STATUS_ERROR | LOG_ALL | LOG_CALLS) : 0;
    instance_reset(instance);
    if (instance_recording(instance))
        instance_record_call(instance, function, instance->data.time, STATUS_OK, "interface=%s",
                             type == INTERFACE_CO_SIMULATION ? "CoSimulation" : "ModelExchange");
    return instance;
}

void instance_free(Instance *instance) {
    if (!instance) return; /* both standards: freeing NULL is ignored */
    instance_free_states(instance);
    if (instance->record_file) record_file_close(instance->record_file);
    free(instance);
}

void instance_reset(Instance *instance) {
    InstanceData *data = &instance->data;
    memset(data, 0, sizeof(*data));
    data->machine_state = STATE_INSTANTIATED;
    data->tolerance = DEFAULT_TOLERANCE;
    for (size_t vr = 0; vr < N_VARIABLES; vr++) data->values[vr] = model_variables[vr].start;
    instance_data_changed(instance);
}

void instance_data_changed(Instance *instance) {
    model_coefficients(instance->data.values, &instance->coefficients);
    instance->outputs_stale = 1;
}

Status instance_set_debug_logging(Instance *instance, const char *function, int logging_on,
                                  size_t n_categories, const char *const categories[]) {
    int bits = 0;
    if (n_categories == 0) {
        bits = LOG_STATUS_WARNING | LOG_STATUS_DISCARD | LOG_STATUS_ERROR | LOG_ALL | LOG_CALLS;
    } else {
        if (instance_null_argument(instance, function, "categories", categories))
            return STATUS_ERROR;
        for (size_t i = 0; i < n_categories; i++) {
            size_t c = 0;
            while (c < N_CATEGORIES && !(categories[i] && strcmp(categories[i], category_names[c]) == 0)) c++;
            if (c == N_CATEGORIES)
                return instance_error(instance, function, "unknown log category %s",
                                      categories[i] ? categories[i] : "NULL");
            bits |= 1 << c;
        }
    }
    instance->log_categories = logging_on ? (instance->log_categories | bits)
                                          : (instance->log_categories & ~bits);
    return STATUS_OK;
}

Status instance_setup_experiment(Instance *instance, const char *function, int tolerance_defined,
                                 double tolerance, double start_time) {
    if (!isfinite(start_time))
        return instance_error(instance, function, "startTime must be finite");
    if (tolerance_defined) {
        if (!(tolerance > 0 && tolerance < 1))
            return instance_error(instance, function, "tolerance %g must be in (0, 1)", tolerance);
        instance->data.tolerance = tolerance;
    }
    instance->data.time = start_time;
    instance->data.last_successful_time = start_time;
    return STATUS_OK;
}

Status instance_exit_initialization(Instance *instance, const char *function) {
    const char *problem = model_invalid_parameters(instance->data.values);
    if (problem) return instance_error(instance, function, "%s", problem);
    for (size_t vr = 0; vr < N_VARIABLES; vr++) {
        if (!isfinite(instance->data.values[vr]))
            return instance_error(instance, function, "%s is not finite", model_variables[vr].name);
    }
    instance_data_changed(instance);
    instance->data.machine_state =
        instance->type == INTERFACE_CO_SIMULATION ? STATE_STEP_COMPLETE : STATE_EVENT_MODE;
    return STATUS_OK;
}

int instance_known_references(const Instance *instance, const char *function,
                              const unsigned int vr[], size_t nvr) {
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES) {
            instance_error(instance, function, "vr %u is not a value reference of this FMU", vr[i]);
            return 0;
        }
    }
    return 1;
}

/* Why a variable may not be set in this state, or NULL when it may (FMI 2.0 section 3.2.3, FMI 3.0 section 2.2.4). */
static const char *why_not_settable(const VariableInfo *variable, int state) {
    /* Inputs first, as they are set every step: in every state a setter is allowed in. */
    if (variable->causality == CAUSALITY_INPUT) return NULL;
    const int exact = variable->initial == INITIAL_EXACT;
    const int tunable = variable->variability == VARIABILITY_TUNABLE;
    if (variable->variability == VARIABILITY_CONSTANT) return "it is a constant";
    if (variable->initial == INITIAL_CALCULATED) return "it is calculated by the FMU";
    switch (state) {
        case STATE_INSTANTIATED:
            return exact || variable->initial == INITIAL_APPROX ? NULL : "not before initialization";
        case STATE_INITIALIZATION_MODE:
            return exact ? NULL : "not in initialization mode";
        default:
            if (variable->causality == CAUSALITY_PARAMETER && tunable) return NULL;
            return variable->causality == CAUSALITY_PARAMETER
                       ? "a fixed parameter cannot change after initialization"
                       : "it can be set only before initialization ends";
    }
}

Status instance_set_real(Instance *instance, const char *function, const unsigned int vr[],
                         size_t nvr, const double value[]) {
    /* All checked before any is set, so a refused call changes nothing. */
    if (!instance_known_references(instance, function, vr, nvr)) return STATUS_ERROR;
    for (size_t i = 0; i < nvr; i++) {
        const VariableInfo *variable = &model_variables[vr[i]];
        const char *problem = why_not_settable(variable, instance->data.machine_state);
        if (problem) return instance_error(instance, function, "cannot set %s: %s", variable->name,
                                           problem);
        if (!isfinite(value[i]))
            return instance_error(instance, function,
                                  "%s = %g refused: values must be finite; %s keeps %.17g",
                                  variable->name, value[i], variable->name,
                                  instance->data.values[vr[i]]);
    }
    int parameters_changed = 0;
    for (size_t i = 0; i < nvr; i++) {
        instance->data.values[vr[i]] = value[i];
        parameters_changed |= model_variables[vr[i]].causality == CAUSALITY_PARAMETER;
    }
    if (parameters_changed) model_coefficients(instance->data.values, &instance->coefficients);
    if (nvr > 0) instance->outputs_stale = 1;
    return STATUS_OK;
}

Status instance_get_real(Instance *instance, const char *function, const unsigned int vr[],
                         size_t nvr, double value[]) {
    if (!instance_known_references(instance, function, vr, nvr)) return STATUS_ERROR;
    for (size_t i = 0; i < nvr; i++) {
        /* Calculated outputs are brought up to date only when one is asked for. */
        if (instance->outputs_stale && model_variables[vr[i]].initial == INITIAL_CALCULATED) {
            model_update_outputs(&instance->coefficients, instance->data.values);
            instance->outputs_stale = 0;
        }
        value[i] = instance->data.values[vr[i]];
    }
    return STATUS_OK;
}

Status instance_set_input_derivatives(Instance *instance, const char *function,
                                      const unsigned int vr[], size_t nvr, const int order[],
                                      const double value[]) {
    if (instance->type != INTERFACE_CO_SIMULATION)
        return instance_error(instance, function, "input derivatives are for co-simulation only");
    if (!instance_known_references(instance, function, vr, nvr)) return STATUS_ERROR;
    for (size_t i = 0; i < nvr; i++) {
        const VariableInfo *variable = &model_variables[vr[i]];
        if (variable->causality != CAUSALITY_INPUT)
            return instance_error(instance, function, "%s is not an input", variable->name);
        if (order[i] < 1)
            return instance_error(instance, function, "order %d for %s: orders start at 1",
                                  order[i], variable->name);
        if (!isfinite(value[i]))
            return instance_error(instance, function, "derivative of %s = %g refused: must be finite",
                                  variable->name, value[i]);
    }
    Status status = STATUS_OK;
    for (size_t i = 0; i < nvr; i++) {
        if (order[i] == 1) {
            instance->data.inputs.first[vr[i]] = value[i];
        } else if (order[i] == 2) {
            instance->data.inputs.second[vr[i]] = value[i];
        } else if (!instance->ignored_orders_logged) {
            /* An extrapolating master sends every order up to maxOutputDerivativeOrder of the
               FMU it connects; a quadratic over one step is all the accuracy the integrator
               can use, so the rest is ignored rather than refused. */
            instance->ignored_orders_logged = 1;
            instance_log(instance, STATUS_WARNING, LOG_STATUS_WARNING,
                         "%s: order %d for %s ignored: inputs follow their first and second "
                         "derivatives only (logged once per instance)", function, order[i],
                         model_variables[vr[i]].name);
            status = STATUS_WARNING;
        }
    }
    return status;
}

Status instance_get_output_derivatives(Instance *instance, const char *function,
                                       const unsigned int vr[], size_t nvr, const int order[],
                                       double value[]) {
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES ||
            !model_output_derivative(&instance->coefficients, instance->data.values,
                                     &instance->data.inputs, vr[i], order[i], &value[i]))
            return instance_error(instance, function,
                                  "no derivative of order %d for vr %u (the model description's "
                                  "outputs and maxOutputDerivativeOrder say which there are)",
                                  order[i], vr[i]);
    }
    return STATUS_OK;
}

/* d unknown / d known, or 0 after logging why there is none. */
static int partial(Instance *instance, const char *function, unsigned int unknown,
                   unsigned int known, double *value) {
    if (unknown < N_VARIABLES && known < N_VARIABLES &&
        model_partial_derivative(&instance->coefficients, instance->data.values, unknown, known, value))
        return 1;
    instance_error(instance, function, "no partial derivative of vr %u with respect to vr %u",
                   unknown, known);
    return 0;
}

Status instance_directional_derivative(Instance *instance, const char *function,
                                       const unsigned int unknown[], size_t n_unknown,
                                       const unsigned int known[], size_t n_known,
                                       const double known_delta[], double unknown_delta[]) {
    for (size_t i = 0; i < n_unknown; i++) {
        double sum = 0.0, value;
        for (size_t j = 0; j < n_known; j++) {
            if (!partial(instance, function, unknown[i], known[j], &value)) return STATUS_ERROR;
            sum += value * known_delta[j];
        }
        unknown_delta[i] = sum;
    }
    return STATUS_OK;
}

Status instance_adjoint_derivative(Instance *instance, const char *function,
                                   const unsigned int unknown[], size_t n_unknown,
                                   const unsigned int known[], size_t n_known,
                                   const double unknown_seed[], double known_sensitivity[]) {
    for (size_t j = 0; j < n_known; j++) {
        double sum = 0.0, value;
        for (size_t i = 0; i < n_unknown; i++) {
            if (!partial(instance, function, unknown[i], known[j], &value)) return STATUS_ERROR;
            sum += unknown_seed[i] * value;
        }
        known_sensitivity[j] = sum;
    }
    return STATUS_OK;
}

static void derivatives(const void *context, double offset, const double x[N_STATES],
                        double dx[N_STATES]) {
    const Instance *instance = context;
    model_derivatives(&instance->coefficients, instance->data.values, &instance->data.inputs,
                      offset, x, dx);
}

static int taylor_series(const void *context, double offset, double h,
                         double series[TAYLOR_ORDER + 1][N_STATES]) {
    const Instance *instance = context;
    return model_taylor_series(&instance->coefficients, instance->data.values,
                               &instance->data.inputs, offset, h, series);
}

Status instance_do_step(Instance *instance, const char *function, double communication_point,
                        double communication_step) {
    InstanceData *data = &instance->data;
    if (!(communication_step > 0) || !isfinite(communication_step))
        return instance_error(instance, function,
                              "communicationStepSize %g must be positive and finite",
                              communication_step);
    const double time_scale = fabs(data->time) > 1.0 ? fabs(data->time) : 1.0;
    if (!(fabs(communication_point - data->time) <= TIME_MATCH_TOLERANCE * time_scale))
        return instance_error(instance, function,
                              "currentCommunicationPoint %.17g is not where the instance stands "
                              "(%.17g)", communication_point, data->time);
    const double end_time = communication_point + communication_step;
    if (!isfinite(end_time))
        return instance_error(instance, function,
                              "a step of %g from t = %.17g ends past the largest time a double holds",
                              communication_step, communication_point);

#if N_INPUTS > 0
    /* Where the inputs' polynomials take them by the step's end (a held input, the usual case,
       stays): past the largest double, the step is refused before anything moves. */
    static const int inputs[N_INPUTS] = INPUT_REFERENCES;
    double end_values[N_INPUTS], end_first[N_INPUTS];
    int moving = 0;
    for (int i = 0; i < N_INPUTS; i++) {
        const int vr = inputs[i];
        if (data->inputs.first[vr] == 0 && data->inputs.second[vr] == 0) {
            end_values[i] = data->values[vr];
            end_first[i] = 0;
            continue;
        }
        moving = 1;
        end_values[i] = input_at(data->values, &data->inputs, vr, communication_step);
        end_first[i] = data->inputs.first[vr] + communication_step * data->inputs.second[vr];
        if (!isfinite(end_values[i]) || !isfinite(end_first[i]))
            return instance_error(instance, function,
                                  "the input derivatives take %s past the largest number a double "
                                  "holds within this step of %g: take smaller steps or set smaller "
                                  "derivatives", model_variables[vr].name, communication_step);
    }
#endif

    double x[N_STATES];
    double step_size = data->step_size;
    long steps;
    model_get_states(data->values, x);
    const IntegrationResult result = integrate(derivatives, taylor_series, instance, x,
                                               communication_step, data->tolerance,
                                               data->tolerance, MAX_INTERNAL_STEPS, &step_size,
                                               &steps);
    if (result != INTEGRATION_OK) {
        data->machine_state = STATE_STEP_FAILED;
        instance_log(instance, STATUS_DISCARD, LOG_STATUS_DISCARD,
                     "%s: step from t = %.17g of size %g discarded after %ld internal steps: "
                     "%s at tolerance %g; the instance stays at t = %.17g (restore an FMU state "
                     "or take smaller steps)",
                     function, communication_point, communication_step, steps,
                     result == INTEGRATION_STEP_BUDGET_EXHAUSTED ? "step budget exhausted"
                                                                 : "step size underflow",
                     data->tolerance, data->time);
        return STATUS_DISCARD;
    }
#if N_INPUTS > 0
    for (int i = 0; moving && i < N_INPUTS; i++) {
        data->values[inputs[i]] = end_values[i];
        data->inputs.first[inputs[i]] = end_first[i];
    }
#endif
    model_set_states(data->values, x);
    data->step_size = step_size;
    data->time = end_time;
    data->last_successful_time = data->time;
    instance->outputs_stale = 1;
    return STATUS_OK;
}

static int wrong_state_count(const Instance *instance, const char *function, size_t nx) {
    if (nx == N_STATES) return 0;
    instance_error(instance, function, "nx = %lu, but the model has %d continuous states",
                   (unsigned long)nx, N_STATES);
    return 1;
}

Status instance_set_time(Instance *instance, const char *function, double time) {
    if (!isfinite(time)) return instance_error(instance, function, "time must be finite");
    instance->data.time = time;
    return STATUS_OK;
}

Status instance_set_states(Instance *instance, const char *function, const double x[], size_t nx) {
    if (wrong_state_count(instance, function, nx)) return STATUS_ERROR;
    for (size_t i = 0; i < nx; i++) {
        if (!isfinite(x[i]))
            return instance_error(instance, function, "x[%lu] = %g refused: states must be finite",
                                  (unsigned long)i, x[i]);
    }
    model_set_states(instance->data.values, x);
    instance->outputs_stale = 1;
    return STATUS_OK;
}

Status instance_get_states(Instance *instance, const char *function, double x[], size_t nx) {
    if (wrong_state_count(instance, function, nx)) return STATUS_ERROR;
    model_get_states(instance->data.values, x);
    return STATUS_OK;
}

Status instance_get_derivatives(Instance *instance, const char *function, double dx[], size_t nx) {
    if (wrong_state_count(instance, function, nx)) return STATUS_ERROR;
    double x[N_STATES];
    model_get_states(instance->data.values, x);
    model_derivatives(&instance->coefficients, instance->data.values, &instance->data.inputs, 0.0,
                      x, dx);
    return STATUS_OK;
}

Status instance_get_nominals(Instance *instance, const char *function, double nominals[], size_t nx) {
    if (wrong_state_count(instance, function, nx)) return STATUS_ERROR;
    for (size_t i = 0; i < nx; i++) nominals[i] = 1.0; /* the states are of order one in SI */
    return STATUS_OK;
}
