#ifndef MODEL_H
#define MODEL_H

/* The interface between the FMI plumbing and a model. The plumbing stores every variable in one
   array indexed by value reference (values[]) and never looks at what the numbers mean. Each
   model brings, in its own folder, config.h (its traits N_STATES, HAS_EVENTS and FLOAT64_ONLY, and
   its ModelCoefficients) and model.c. */

#include "config.h"
#include "model_variables.h"

#if !defined(N_STATES) || !defined(HAS_EVENTS) || !defined(FLOAT64_ONLY)
#error "the model's config.h must define N_STATES, HAS_EVENTS and FLOAT64_ONLY"
#endif

/* What a master said of how its inputs move over a step: first and second time derivatives at
   the step's start (FMI 2.0's input derivatives; all zero holds the inputs). */
typedef struct {
    double first[N_VARIABLES];
    double second[N_VARIABLES];
} InputDerivatives;

/* Input vr `offset` seconds into a step: its Taylor polynomial from the step's start. */
static inline double input_at(const double values[N_VARIABLES], const InputDerivatives *derivatives,
                              int vr, double offset) {
    return values[vr] + offset * (derivatives->first[vr] + 0.5 * offset * derivatives->second[vr]);
}

/* NULL when the parameters make sense, else what is wrong with them. */
const char *model_invalid_parameters(const double values[N_VARIABLES]);

void model_coefficients(const double values[N_VARIABLES], ModelCoefficients *coefficients);

void model_get_states(const double values[N_VARIABLES], double x[N_STATES]);
void model_set_states(double values[N_VARIABLES], const double x[N_STATES]);

/* dx/dt at `offset` seconds into a communication step, the inputs at input_at(offset). */
void model_derivatives(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                       const InputDerivatives *inputs, double offset,
                       const double x[N_STATES], double dx[N_STATES]);

/* The order of the Taylor method's series (integrator.c): the lowest at which no step of the
   pendulum is less exact than DOPRI5's (order 5) at any tolerance and communication step (at
   order 5, 10 ms steps came out 5 times less exact). */
#define TAYLOR_ORDER 6

/* The Taylor series of the states for the Taylor method, at `offset` seconds into a
   communication step with the inputs on their polynomials, scaled by the step h: row k holds
   h^k/k! times the k-th time derivatives, so that a state's rows sum to its value h later.
   Row 0 holds the states; the function fills in the rest. Returns 0 when the model has no
   series: DOPRI5 integrates it then. */
int model_taylor_series(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                        const InputDerivatives *inputs, double offset, double h,
                        double series[TAYLOR_ORDER + 1][N_STATES]);

/* Brings the calculated outputs in values[] up to date with the states and inputs. */
void model_update_outputs(const ModelCoefficients *coefficients, double values[N_VARIABLES]);

/* The order-th time derivative of an output; returns 0 when vr or order is not supported. */
int model_output_derivative(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                            const InputDerivatives *inputs, unsigned int vr, int order,
                            double *derivative);

/* d(unknown)/d(known) for unknown an output or state derivative and known an input or state;
   returns 0 when the pair is not one the model provides. */
int model_partial_derivative(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                             unsigned int unknown, unsigned int known, double *partial);

#endif
