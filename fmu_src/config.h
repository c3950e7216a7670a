#ifndef CONFIG_H
#define CONFIG_H

/* The pendulum's states are theta and omega. */
#define N_STATES 2

/* Derived once from the fixed parameters, so a right-hand side costs one sin(). */
typedef struct {
    double gravity_moment;   /* mass*gravity*length */
    double damping;
    double inverse_inertia;  /* 1/(inertia + mass*length^2) */
} ModelCoefficients;

#endif
