/* escape_text (fmu_src/src/record_file.c) on the command line's cases: each line of stdin is a
   buffer size and a string in hex ("16 410a"); each line of stdout is what escape_text wrote into
   a buffer of that size, and its length. */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "record_file.h"

int main(void) {
    char hex[4096], text[2048], out[8192];
    size_t size;
    while (scanf("%zu %4095s", &size, hex) == 2) {
        size_t n = strlen(hex) / 2;
        for (size_t i = 0; i < n; i++) {
            unsigned byte;
            sscanf(hex + 2 * i, "%2x", &byte);
            text[i] = (char)byte;
        }
        text[n] = '\0';
        memset(out, 'Z', sizeof(out));
        escape_text(out, size, text);
        /* A size of 0 writes nothing, not even the terminating zero. */
        printf("%s\n", size ? out : "");
    }
    return 0;
}
