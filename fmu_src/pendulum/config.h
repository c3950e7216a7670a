#ifndef CONFIG_H
#define CONFIG_H

/* The model's traits, which the FMI plumbing (fmu_src/src/) reads: the pendulum's states are theta
   and omega, it has no events (no event indicators, no discrete states) and all its variables are
   Float64 (FMI 2.0 Real). */
#define N_STATES 2
#define HAS_EVENTS 0
#define FLOAT64_ONLY 1

/* Derived once from the fixed parameters, so a right-hand side costs one sin(). */
typedef struct {
    double gravity_moment;   /* mass*gravity*length */
    double damping;
    double inverse_inertia;  /* 1/(inertia + mass*length^2) */
} ModelCoefficients;

#endif
