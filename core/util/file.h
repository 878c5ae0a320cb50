/* file.h — reading input files whole, and where libmurk's own file is. Internal to libmurk. Errors are
 * "path: what is wrong". */
#ifndef MURK_FILE_H
#define MURK_FILE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Opens a regular file for reading and gives its size; NULL with err set otherwise. Anything else —
 * a directory, a FIFO, a device such as /dev/zero — is refused before a byte is read (a FIFO does not
 * block the open), and so is a file larger than MURK_MAX_FILE_BYTES (limit.h). */
FILE *murk_file_open_regular(const char *path, uint64_t *size, char *err, size_t errlen);
/* The same as a descriptor (O_RDONLY | O_CLOEXEC, blocking); -1 with err set. */
int murk_file_open_regular_fd(const char *path, uint64_t *size, char *err, size_t errlen);
/* Reads a whole regular file into malloc'd memory that has 8 spare bytes after the content; NULL with
 * err set on failure. */
unsigned char *murk_file_read_all(const char *path, uint64_t *size, char *err, size_t errlen);
/* The folder of the file this code was loaded from: libmurk.so's, or an executable's that links murk's
 * objects statically (the tests), with symbolic links resolved. 0, or -1 if it is unknown or longer than n. */
int murk_library_dir(char *out, size_t n);

#endif
