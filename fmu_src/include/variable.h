#ifndef VARIABLE_H
#define VARIABLE_H

/* What the FMI plumbing must know of a variable to police the setters. The table of these is
   generated from modelDescription.xml by the build, so the C code cannot drift from the XML. */

typedef enum {
    CAUSALITY_PARAMETER,
    CAUSALITY_CALCULATED_PARAMETER,
    CAUSALITY_INPUT,
    CAUSALITY_OUTPUT,
    CAUSALITY_LOCAL,
    CAUSALITY_INDEPENDENT
} Causality;

typedef enum {
    VARIABILITY_CONSTANT,
    VARIABILITY_FIXED,
    VARIABILITY_TUNABLE,
    VARIABILITY_DISCRETE,
    VARIABILITY_CONTINUOUS
} Variability;

typedef enum {
    INITIAL_NONE,
    INITIAL_EXACT,
    INITIAL_APPROX,
    INITIAL_CALCULATED
} Initial;

typedef struct {
    const char *name;
    Causality causality;
    Variability variability;
    Initial initial;
    double start;
} VariableInfo;

#endif
