/* A generic FMI 2.0 co-simulation loop: one call runs a whole case through the FMU's own exported
   FMI functions: optionally a restart (fmi2Reset and initialization with new start values), then
   every communication step (fmi2SetReal, fmi2SetRealInputDerivatives, fmi2GetReal, fmi2DoStep).

   Plain C99, not a CPython module: Python loads it with ctypes and passes the addresses of the
   functions of the FMU library fmpy already loaded, the instance, and numpy buffers. Nothing is
   allocated here, so the cost of a step is the FMU's own work plus four indirect calls, and the
   cost of a restart is the FMU's own.

   The call sequence is the one of the Python code in pendulum_fmu/fmu/_simulate.py (initialize and
   the loop of run_schedule_python, the readable reference), so the two give bit-identical
   results: per step k, set the inputs, set their first derivatives (when rates are given), read
   the outputs, step from time[k] by time[k+1] - time[k]; after the last step read the outputs
   once more.

   cs_loop_run_cases runs a chunk of cases (a parameter study's) in one call: each case a restart
   with its own start values, then every step with no input set, into one preallocated array. */

#include "_cs_loop.h"

/* Changes whenever the arguments of cs_loop_run, cs_loop_run_cases or the batch's functions
   (_cs_batch.c) do, so that Python never calls a stale build with the wrong arguments
   (_native_loop.py checks it). */
CS_LOOP_EXPORT int cs_loop_interface(void) { return 7; }

/* Runs one case.

   start_values[i]                   when not NULL, the instance is first reset and initialized
                                     again, with start_references[i] set to start_values[i] in
                                     initialization mode, at start time time[0] with relative
                                     tolerance *tolerance (none when tolerance is NULL; no stop
                                     time); when NULL it must be initialized already
   time[0..n_steps]                  communication points
   inputs[k*n_inputs + i]            input i over step k (the value at the step's start)
   input_rates[k*n_inputs + i]       its derivative of order input_orders[i] (1 for a ramp) over
                                     step k, or input_rates == NULL to hold the inputs
                                     (fmi2SetRealInputDerivatives is not called)
   outputs[k*n_outputs + j]          output j at point k (k = 0..n_steps), read after the
                                     inputs of step k were set

   Returns fmi2OK or fmi2Warning when every call succeeded (a warning is the worst status seen),
   else the failing call's status, with *failed_step = k (0 for the restart, n_steps for the
   reads at the end) and *failed_call one of the CALL_ values; the outputs before the failure
   are filled in. */
CS_LOOP_EXPORT int cs_loop_run(
    const CsFunctions *fmi, fmi2Component component,
    const fmi2ValueReference *start_references, size_t n_start, const double *start_values,
    const double *tolerance, const fmi2ValueReference *input_references, size_t n_inputs,
    const fmi2ValueReference *output_references, size_t n_outputs,
    size_t n_steps, const double *time, const double *inputs,
    const fmi2Integer *input_orders, const double *input_rates,
    double *outputs,
    size_t *failed_step, int *failed_call)
{
    fmi2Status worst = fmi2OK, status;
    size_t k = 0;

#define CHECK(call_expression, which)                                                   \
    do {                                                                                \
        status = (call_expression);                                                     \
        if (status > fmi2Warning) { *failed_step = k; *failed_call = (which); return (int)status; } \
        if (status > worst) worst = status;                                             \
    } while (0)

    if (start_values != NULL) {
        CHECK(fmi->reset(component), CALL_RESET);
        CHECK(fmi->setup_experiment(component, tolerance != NULL, tolerance ? *tolerance : 0.0,
                                    time[0], fmi2False, 0.0),
              CALL_SETUP_EXPERIMENT);
        CHECK(fmi->enter_initialization_mode(component), CALL_ENTER_INITIALIZATION_MODE);
        if (n_start)
            CHECK(fmi->set_real(component, start_references, n_start, start_values),
                  CALL_SET_START_VALUES);
        CHECK(fmi->exit_initialization_mode(component), CALL_EXIT_INITIALIZATION_MODE);
    }
    for (k = 0; k < n_steps; k++) {
        if (n_inputs) {
            CHECK(fmi->set_real(component, input_references, n_inputs, inputs + k * n_inputs),
                  CALL_SET_REAL);
            if (input_rates != NULL)
                CHECK(fmi->set_real_input_derivatives(component, input_references, n_inputs,
                                                      input_orders, input_rates + k * n_inputs),
                      CALL_SET_RATE);
        }
        CHECK(fmi->get_real(component, output_references, n_outputs, outputs + k * n_outputs),
              CALL_GET_REAL);
        CHECK(fmi->do_step(component, time[k], time[k + 1] - time[k], fmi2True), CALL_DO_STEP);
    }
    CHECK(fmi->get_real(component, output_references, n_outputs, outputs + k * n_outputs),
          CALL_GET_OUTPUTS_AT_END);
#undef CHECK
    return (int)worst;
}

/* Runs cases one after the other, each a restart of the instance (fmi2Reset, initialization at
   time[0] with its start values, as cs_loop_run with start values) and then every step, with no
   input set: what a parameter study's chunk of cases needs, with no call back into Python.

   start_values[c*n_start + i]       start value i of case c (start_references[i])
   case_outputs[k*n_outputs + j]     room for one case's outputs as cs_loop_run writes them
                                     ((n_steps+1) * n_outputs values, the caller's)
   outputs[(j*n_cases + c)*(n_steps+1) + k]
                                     output j of case c at point k: each output's values of the
                                     whole chunk are one contiguous series, a table column as it
                                     is (a transpose here, of one case that is still in cache,
                                     costs less than gathering a strided column afterwards)

   Returns as cs_loop_run, for the cases run: it stops at the first case whose calls fail, with
   *failed_case = its index among the cases given (its outputs not filled in), so that the
   caller takes the FMU's messages for that case before it runs the rest (a restart starts with
   fmi2Reset, so a refused case leaves nothing to the next): first_case is where to go on. */
CS_LOOP_EXPORT int cs_loop_run_cases(
    const CsFunctions *fmi, fmi2Component component,
    const fmi2ValueReference *start_references, size_t n_start, const double *start_values,
    const double *tolerance, const fmi2ValueReference *output_references, size_t n_outputs,
    size_t n_cases, size_t first_case, size_t n_steps, const double *time,
    double *case_outputs, double *outputs,
    size_t *failed_case, size_t *failed_step, int *failed_call)
{
    int worst = fmi2OK, status;
    size_t c, j, k, points = n_steps + 1;
    for (c = first_case; c < n_cases; c++) {
        status = cs_loop_run(fmi, component, start_references, n_start, start_values + c * n_start,
                             tolerance, NULL, 0, output_references, n_outputs, n_steps, time,
                             NULL, NULL, NULL, case_outputs, failed_step, failed_call);
        if (status > fmi2Warning) { *failed_case = c; return status; }
        if (status > worst) worst = status;
        for (j = 0; j < n_outputs; j++) {
            double *series = outputs + (j * n_cases + c) * points;
            for (k = 0; k < points; k++)
                series[k] = case_outputs[k * n_outputs + j];
        }
    }
    return worst;
}
