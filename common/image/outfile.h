/*
 * outfile.h: an output file that appears complete or not at all
 * (image_outfile).
 *
 * Every image aafarm writes (the EXR, the PNG preview) goes to a temporary
 * file next to its final name, "OUT.tmp-<pid>" for final name "OUT", opened
 * with O_EXCL. Committing flushes it to disk (fsync) and renames it over
 * the final name, which POSIX makes atomic within one file system: readers
 * see the old file or the new one, never half of one. Destroying an
 * uncommitted outfile (an abort) unlinks the temporary file and leaves any
 * existing final file untouched. A process killed mid-write leaves only
 * its "*.tmp-<pid>" file behind, never a half-written final file.
 */
#ifndef IMAGE_OUTFILE_H
#define IMAGE_OUTFILE_H

#include <stdbool.h>
#include <stddef.h>

typedef struct image_outfile image_outfile;

/* Creates the temporary file for final path `path`; NULL with the reason
 * in err (directory missing, not writable, temp file already exists). */
image_outfile *image_outfile_new(const char *path, char *err, size_t errsz);

/* Aborts when not committed: closes and unlinks the temporary file. */
void image_outfile_destroy(image_outfile **self_p);

int image_outfile_fd(const image_outfile *self);
const char *image_outfile_path(const image_outfile *self);
const char *image_outfile_temp_path(const image_outfile *self);

/* fsync, close, rename over the final path. Always destroys the outfile;
 * on failure the temporary file is removed and err says why. */
bool image_outfile_commit(image_outfile **self_p, char *err, size_t errsz);

#endif
