/* file.h — reading input files whole. Internal to libmurk. Errors are "path: what is wrong". */
#ifndef MURK_FILE_H
#define MURK_FILE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Opens a regular file for reading and gives its size; NULL with err set otherwise. */
FILE *murk_file_open_regular(const char *path, uint64_t *size, char *err, size_t errlen);
/* Reads a whole regular file into malloc'd memory that has 8 spare bytes after the content; NULL with
 * err set on failure. */
unsigned char *murk_file_read_all(const char *path, uint64_t *size, char *err, size_t errlen);

#endif
