/* glibc hides POSIX 2008 (open's O_NOFOLLOW and O_CLOEXEC, pread, fdopen) from strict C99
   unless asked; macOS shows it by default and would hide its own names if asked. */
#if defined(__linux__) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L
#endif

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "record_file.h"

/* The escape of one byte into escape (5 bytes); returns its length. */
static size_t escape_byte(unsigned char c, char escape[5]) {
    static const char hex[] = "0123456789abcdef";
    if (c == '\\' || c == '"') return (size_t)snprintf(escape, 5, "\\%c", c);
    if (c == '\t') return (size_t)snprintf(escape, 5, "\\t");
    if (c == '\n') return (size_t)snprintf(escape, 5, "\\n");
    if (c == '\r') return (size_t)snprintf(escape, 5, "\\r");
    if (c < 0x20 || c > 0x7e || c == '%')
        return (size_t)snprintf(escape, 5, "\\x%c%c", hex[c >> 4], hex[c & 15]);
    return (size_t)snprintf(escape, 5, "%c", c);
}

const char *escape_text(char *out, size_t size, const char *text) {
    char escape[5];
    size_t total = 0, used = 0;
    if (!size) return out;
    /* Only whether it all fits matters, so a megabyte from a master costs no more than size. */
    for (const char *c = text; c && *c && total < size; c++) total += escape_byte((unsigned char)*c, escape);
    /* Cut: room for "..." and the terminating zero after the last whole escape. */
    const size_t limit = total < size ? total : size > 4 ? size - 4 : 0;
    for (const char *c = text; c && *c; c++) {
        const size_t length = escape_byte((unsigned char)*c, escape);
        if (used + length > limit) break;
        memcpy(out + used, escape, length);
        used += length;
    }
    if (total >= size && size > 4) {
        memcpy(out + used, "...", 3);
        used += 3;
    }
    out[used] = '\0';
    return out;
}

#if !defined(__wasm__)
static int starts_with_marker(const char *head, size_t read, const char *marker) {
    return read == strlen(marker) && memcmp(head, marker, read) == 0;
}
#endif

#if defined(__wasm__)
/* A WebAssembly component of the FMU imports nothing but the FMI callbacks (no WASI file system),
   so it has no file to open: the record goes to the logger alone (category logCalls,
   RECORD_FILE_ADVICE). Nothing is ever opened, so nothing is ever written or closed, and no file
   function is linked in. */
FILE *record_file_open(const char *name, const char *marker, char *why, size_t why_size) {
    (void)name, (void)marker;
    snprintf(why, why_size, "cannot be opened: the WebAssembly binary has no files");
    return NULL;
}

void record_file_append(FILE *file, const char *line) { (void)file, (void)line; }

void record_file_close(FILE *file) { (void)file; }

#elif defined(_WIN32)
#include <fcntl.h>
#include <io.h>
#include <stdint.h>
#include <windows.h>

/* Windows has no owner-only mode bits to give a new file: it takes its folder's permissions. */
FILE *record_file_open(const char *name, const char *marker, char *why, size_t why_size) {
    const DWORD access = FILE_APPEND_DATA | FILE_READ_DATA | FILE_READ_ATTRIBUTES | SYNCHRONIZE;
    const DWORD share = FILE_SHARE_READ | FILE_SHARE_WRITE;
    /* The link itself, not what it points to, is opened: then it is refused below. */
    const DWORD flags = FILE_ATTRIBUTE_NORMAL | FILE_FLAG_OPEN_REPARSE_POINT;
    int created = 1;
    HANDLE file = CreateFileA(name, access, share, NULL, CREATE_NEW, flags, NULL);
    if (file == INVALID_HANDLE_VALUE && GetLastError() == ERROR_FILE_EXISTS) {
        created = 0;
        file = CreateFileA(name, access, share, NULL, OPEN_EXISTING, flags, NULL);
    }
    if (file == INVALID_HANDLE_VALUE) {
        snprintf(why, why_size, "cannot be opened for appending (Windows error %lu)",
                 (unsigned long)GetLastError());
        return NULL;
    }
    const char *refusal = NULL;
    if (!created) {
        BY_HANDLE_FILE_INFORMATION information;
        char head[64];
        DWORD read = 0;
        const DWORD wanted = (DWORD)strlen(marker);
        if (!GetFileInformationByHandle(file, &information))
            refusal = "cannot be examined";
        else if (information.dwFileAttributes & FILE_ATTRIBUTE_REPARSE_POINT)
            refusal = "is a link";
        else if (GetFileType(file) != FILE_TYPE_DISK
                 || (information.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY))
            refusal = "is not a regular file";
        else if (information.nNumberOfLinks != 1)
            refusal = "has other hard links";
        else if (wanted > sizeof(head) || !ReadFile(file, head, wanted, &read, NULL)
                 || !starts_with_marker(head, read, marker))
            refusal = "is not a call record (its first line is not a record line)";
    }
    if (refusal) {
        CloseHandle(file);
        snprintf(why, why_size, "%s", refusal);
        return NULL;
    }
    const int descriptor = _open_osfhandle((intptr_t)file, _O_APPEND | _O_WRONLY);
    if (descriptor < 0) {
        CloseHandle(file);
        snprintf(why, why_size, "cannot be opened for appending (no descriptor)");
        return NULL;
    }
    FILE *stream = _fdopen(descriptor, "a");
    if (!stream) {
        _close(descriptor);
        snprintf(why, why_size, "cannot be opened for appending (%s)", strerror(errno));
    }
    return stream;
}

#else
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

/* Why an existing file may not take the record, or NULL when it may. */
static const char *refusal(int descriptor, const char *marker) {
    struct stat status;
    char head[64];
    const size_t wanted = strlen(marker);
    if (fstat(descriptor, &status) != 0) return "cannot be examined";
    if (!S_ISREG(status.st_mode)) return "is not a regular file";
    if (status.st_uid != geteuid()) return "belongs to another user";
    if (status.st_nlink != 1) return "has other hard links";
    if (wanted > sizeof(head)) return "is not a call record (its first line is not a record line)";
    const ssize_t read = pread(descriptor, head, wanted, 0);
    if (read < 0 || !starts_with_marker(head, (size_t)read, marker))
        return "is not a call record (its first line is not a record line)";
    return NULL;
}

FILE *record_file_open(const char *name, const char *marker, char *why, size_t why_size) {
    /* O_NOFOLLOW: a link in the last component fails (with O_EXCL, as existing) instead of
       being followed. O_NONBLOCK: a FIFO named here fails the checks instead of blocking. */
    const int common = O_APPEND | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK;
    int descriptor = open(name, O_WRONLY | O_CREAT | O_EXCL | common, S_IRUSR | S_IWUSR);
    if (descriptor < 0 && errno == EEXIST) {
        descriptor = open(name, O_RDWR | common);
        if (descriptor >= 0) {
            const char *why_not = refusal(descriptor, marker);
            if (why_not) {
                close(descriptor);
                snprintf(why, why_size, "%s", why_not);
                return NULL;
            }
        } else if (errno == ELOOP || errno == EMLINK) {
            snprintf(why, why_size, "is a symbolic link");
            return NULL;
        }
    }
    if (descriptor < 0) {
        snprintf(why, why_size, "cannot be opened for appending (%s)", strerror(errno));
        return NULL;
    }
    FILE *stream = fdopen(descriptor, "a");
    if (!stream) {
        snprintf(why, why_size, "cannot be opened for appending (%s)", strerror(errno));
        close(descriptor);
    }
    return stream;
}
#endif

#if !defined(__wasm__)
void record_file_append(FILE *file, const char *line) {
    fprintf(file, "%s\n", line);
    fflush(file);
}

void record_file_close(FILE *file) { fclose(file); }
#endif
