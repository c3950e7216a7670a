#ifndef RECORD_FILE_H
#define RECORD_FILE_H

/* What comes from a master, made safe to write down: its strings escaped for a line of text, and
   the file it names for the call record opened only where a record may go. Nothing here knows FMI
   or the model. */

#include <stddef.h>
#include <stdio.h>

/* Escapes text into out (size bytes) so that no string a master passes can end a line, a quoted
   field or a printf format in a master's logger: a backslash and a double quote become \\ and \",
   tab, newline and carriage return \t, \n and \r, and every other byte outside printable ASCII,
   and '%', \xHH. Only whole escapes are written: when out is too small the text is cut after the
   last that fits and ends with "...", so a cut never leaves a lone backslash. Returns out. */
const char *escape_text(char *out, size_t size, const char *text);

/* The most bytes escape_text writes for a string of length n, its terminating zero included. */
#define ESCAPED_SIZE(n) (4 * (n) + 1)

/* Opens the file name names for appending the call record, only if it is a new file (made here,
   readable and writable by its owner alone) or a regular file of this user's, with one link,
   whose first line is already a record line (starts with marker). The last component of name is
   never followed when it is a link. NULL when refused or failed, with why (at most why_size
   bytes) saying which. */
FILE *record_file_open(const char *name, const char *marker, char *why, size_t why_size);

/* What a master can do when record_file_open refuses: name another file, or, in the WebAssembly
   binary, which has no files, read the record from the logger. */
#if defined(__wasm__)
#define RECORD_FILE_ADVICE "switch on the log category logCalls: the record goes to the logger"
#else
#define RECORD_FILE_ADVICE "name a new file, or one of its records"
#endif

/* Appends one line (line and a newline) to a record file record_file_open opened, flushed at
   once, so that the record is whole up to a master's crash. */
void record_file_append(FILE *file, const char *line);

/* Closes a record file record_file_open opened. */
void record_file_close(FILE *file);

#endif
