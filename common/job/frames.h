/*
 * frames.h: frame sequences (docs/scenes.md "Frames"): every
 * FrameBegin/FrameEnd block of a RIB is a frame; `--frames` chooses some
 * of them by their FrameBegin numbers, and each chosen frame is one job
 * (job_options.frame = its index, so its hash differs from every other
 * frame's) written to its own EXR.
 *
 *   frame_spec_parse     "3", "1-10", "1,3,5-7" -> a frame_spec
 *   frame_output_name    the EXR of one frame, from -o or its Display
 *   frame_sequence_load  the master's and the standalone renderer's entry:
 *                        read the RIB, choose the frames, load and check
 *                        one job per frame, name their outputs
 *
 * Output names: a name with a printf-style frame pattern (%d, %4d, %04d;
 * %% for a percent sign) gets the frame number there. Otherwise, in a file
 * with more than one frame, the frame number (4 digits) is inserted before
 * the extension ("out.exr" -> "out.0003.exr"), except that a Display name
 * already holding the frame number (a run of digits of that value:
 * "anim.0003.exr" in frame 3) is kept as written. Two chosen frames with
 * the same output are an error.
 */
#ifndef JOB_FRAMES_H
#define JOB_FRAMES_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "job/job.h"
#include "sl/diag.h"

/* A choice of frame numbers: ranges lo..hi (inclusive), in the order given. */
typedef struct frame_spec {
    int (*ranges)[2];
    int count;
} frame_spec;

/* Parses text ("3", "1-10", "1,3,5-7"); false with a message naming the
 * bad part in err. Numbers are 0..99999999, ranges low-high. */
bool frame_spec_parse(const char *text, frame_spec *out, char *err, size_t errsz);
void frame_spec_clear(frame_spec *spec);
bool frame_spec_has(const frame_spec *spec, int number);

/* The indices (into numbers[0..n)) of the frames spec chooses (spec NULL:
 * all), in file order, into a malloc'd *indices. False with err when a
 * single number of the spec names no frame, or a range none. A file
 * without FrameBegin (n 0) has one frame, number 1. */
bool frame_choose(const int *numbers, int n, const frame_spec *spec, int **indices,
                  int *count, char *err, size_t errsz);

/* The output of frame `number` from `name` (-o or the frame's Display;
 * display: the name came from the RIB) in a file of `nframes` frames
 * (0 or 1: a single image). malloc'd, or NULL with err (a bad % pattern). */
char *frame_output_name(const char *name, int number, int nframes, bool display,
                        char *err, size_t errsz);

/* One job per chosen frame and its output. */
typedef struct frame_sequence {
    job **jobs;
    char **outputs;
    int count;
    int nframes;                   /* frames in the file (0: no FrameBegin) */
    const char *numbered;          /* a name that got the frame number inserted
                                      (for a note to the user), or NULL */
} frame_sequence;

/* Loads the frames of rib_path that `frames` chooses (NULL: all), each with
 * `options` (NULL: the defaults) and its frame index,
 * by job_load (errors in diag, file:line:col), and names their outputs from
 * `output` (-o; NULL: each frame's Display). NULL on any error: bad spec,
 * a frame that does not load, a frame with no output name, two frames with
 * the same output. *usage says whether the command line is at fault (the
 * spec, a frame it names that is not there, -o missing or not naming each
 * frame apart: exit 2) rather than the scene (exit 3). cancel: the
 * program's stop flag (a signal) or NULL, handed to every parse and
 * job_load (a load it stops fails with "interrupted"). */
frame_sequence *frame_sequence_load(const char *rib_path, const job_options *options,
                                    const char *frames, const char *output, bool *usage,
                                    const atomic_int *cancel, sl_diag *diag);
void frame_sequence_destroy(frame_sequence **self_p);

#endif
