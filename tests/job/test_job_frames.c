/*
 * tests/job/test_job_frames.c: frame sequences in the job model
 * (common/job/frames.c): --frames lists and their errors, which frames a
 * list chooses, the output name of each frame, one job per frame with a
 * hash of its own (a worker can never take frame 2's tile for frame 1's
 * job), and a sequence loaded from a file with its Display names.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "job/frames.h"
#include "job/job_scene.h"

static char dir[256];

static const char *write_rib(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

static void test_spec_parse(void **state)
{
    (void)state;
    frame_spec s;
    char err[300];
    assert_true(frame_spec_parse("3", &s, err, sizeof err));
    assert_int_equal(s.count, 1);
    assert_int_equal(s.ranges[0][0], 3);
    assert_int_equal(s.ranges[0][1], 3);
    frame_spec_clear(&s);
    assert_true(frame_spec_parse("1,3,5-7", &s, err, sizeof err));
    assert_int_equal(s.count, 3);
    assert_true(frame_spec_has(&s, 6));
    assert_true(frame_spec_has(&s, 3));
    assert_false(frame_spec_has(&s, 4));
    assert_false(frame_spec_has(&s, 8));
    frame_spec_clear(&s);

    static const struct { const char *text, *message; } bad[] = {
        { "", "--frames wants frame numbers, e.g. 3, 1-10 or 1,3,5-7; got an empty list" },
        { "1,", "--frames: '' (at character 3 of '1,') is not a frame number 0..99999999 or a "
                "range like 5-7" },
        { "5-", "--frames: '5-' (at character 1 of '5-') is not a frame number 0..99999999 "
                "or a range like 5-7" },
        { "2,x3,4", "--frames: 'x3' (at character 3 of '2,x3,4') is not a frame number "
                    "0..99999999 or a range like 5-7" },
        { "1-2-3", "--frames: '1-2-3' (at character 1 of '1-2-3') is not a frame number "
                   "0..99999999 or a range like 5-7" },
        { "123456789", "--frames: '123456789' (at character 1 of '123456789') is not a frame "
                       "number 0..99999999 or a range like 5-7" },
        { "-3", "--frames: '-3' (at character 1 of '-3') is not a frame number 0..99999999 or "
                "a range like 5-7" },
        { "9-7", "--frames: the range 9-7 runs backwards (write 7-9)" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err[0] = '\0';
        assert_false(frame_spec_parse(bad[i].text, &s, err, sizeof err));
        assert_null(s.ranges);
        assert_string_equal(err, bad[i].message);
    }
}

static void test_choose(void **state)
{
    (void)state;
    static const int numbers[] = {1, 2, 3, 10};
    frame_spec s;
    char err[300];
    int *idx, n;
    assert_true(frame_choose(numbers, 4, NULL, &idx, &n, err, sizeof err));
    assert_int_equal(n, 4);
    free(idx);
    assert_true(frame_spec_parse("10,2-5", &s, err, sizeof err));
    assert_true(frame_choose(numbers, 4, &s, &idx, &n, err, sizeof err));
    assert_int_equal(n, 3);   /* in file order */
    assert_int_equal(idx[0], 1);
    assert_int_equal(idx[1], 2);
    assert_int_equal(idx[2], 3);
    free(idx);
    frame_spec_clear(&s);
    assert_true(frame_spec_parse("2,7", &s, err, sizeof err));
    assert_false(frame_choose(numbers, 4, &s, &idx, &n, err, sizeof err));
    assert_string_equal(err, "--frames: the scene has no frame 7 (its frames: 1-3, 10)");
    frame_spec_clear(&s);
    assert_true(frame_spec_parse("4-9", &s, err, sizeof err));
    assert_false(frame_choose(numbers, 4, &s, &idx, &n, err, sizeof err));
    assert_string_equal(err, "--frames: the scene has no frame in 4-9 (its frames: 1-3, 10)");
    frame_spec_clear(&s);
    /* no FrameBegin: one frame, number 1 */
    assert_true(frame_spec_parse("1", &s, err, sizeof err));
    assert_true(frame_choose(NULL, 0, &s, &idx, &n, err, sizeof err));
    assert_int_equal(n, 1);
    assert_int_equal(idx[0], 0);
    free(idx);
    frame_spec_clear(&s);
}

static void expect_name(const char *name, int number, int nframes, bool display,
                        const char *want)
{
    char err[300] = "";
    char *got = frame_output_name(name, number, nframes, display, err, sizeof err);
    if (!want) {
        assert_null(got);
        assert_non_null(strstr(err, "only %d, %4d, %04d (the frame number) and %% may "
                                    "follow a % sign"));
        return;
    }
    assert_non_null(got);
    assert_string_equal(got, want);
    free(got);
}

static void test_output_names(void **state)
{
    (void)state;
    expect_name("out.exr", 3, 1, false, "out.exr");           /* a single image */
    expect_name("out.exr", 3, 0, false, "out.exr");
    expect_name("out.exr", 3, 5, false, "out.0003.exr");      /* inserted */
    expect_name("out.%04d.exr", 12, 5, false, "out.0012.exr");
    expect_name("out.%d.exr", 12, 5, false, "out.12.exr");
    expect_name("f%4d_%%.exr", 7, 1, false, "f   7_%.exr");
    expect_name("r.v2/out", 5, 3, false, "r.v2/out.0005");    /* no extension */
    expect_name(".hidden", 5, 3, false, ".hidden.0005");
    /* a Display name that holds the frame number is kept; -o is not */
    expect_name("anim.0003.exr", 3, 3, true, "anim.0003.exr");
    expect_name("anim.0003.exr", 4, 3, true, "anim.0003.0004.exr");
    expect_name("anim.0003.exr", 3, 3, false, "anim.0003.0003.exr");
    expect_name("bad%s.exr", 1, 3, false, NULL);
    expect_name("bad%", 1, 3, false, NULL);
}

static const char *SEQUENCE =
    "Format 8 4 1\nProjection \"perspective\"\nTranslate 0 0 5\n"
    "FrameBegin 1\nDisplay \"same.exr\" \"file\" \"rgba\"\n"
    "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\nFrameEnd\n"
    "FrameBegin 2\nDisplay \"same.exr\" \"file\" \"rgba\"\n"
    "WorldBegin\nSphere 2 -2 2 360\nSphere 1 -1 1 360\nWorldEnd\nFrameEnd\n"
    "FrameBegin 4\nDisplay \"four.exr\" \"file\" \"rgba\"\n"
    "WorldBegin\nSphere 2 -2 2 360\nWorldEnd\nFrameEnd\n";

static void test_one_job_per_frame(void **state)
{
    (void)state;
    const char *path = write_rib("seq.rib", SEQUENCE);
    sl_diag *d = sl_diag_new();
    bool usage = true;
    frame_sequence *seq = frame_sequence_load(path, NULL,
                                              NULL, NULL, &usage, NULL, d);
    if (!seq) sl_diag_print(d, stderr);
    assert_non_null(seq);
    assert_false(usage);
    assert_int_equal(seq->count, 3);
    assert_int_equal(seq->nframes, 3);
    /* the names: shared ones get the frame number, one without it too */
    assert_string_equal(seq->outputs[0], "same.0001.exr");
    assert_string_equal(seq->outputs[1], "same.0002.exr");
    assert_string_equal(seq->outputs[2], "four.0004.exr");
    assert_string_equal(seq->numbered, "same.exr");   /* for the note to the user */
    /* three jobs, three hashes; each parses to its own frame */
    assert_string_not_equal(seq->jobs[0]->hash, seq->jobs[1]->hash);
    assert_string_not_equal(seq->jobs[1]->hash, seq->jobs[2]->hash);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(seq->jobs[i]->options.frame, i);
        job_scene *js = job_scene_new(seq->jobs[i], 0, false, NULL, d);
        assert_non_null(js);
        assert_int_equal(js->scene->nobjects, i == 1 ? 2 : 1);
        assert_int_equal(js->scene->frame_number, i == 2 ? 4 : i + 1);
        job_scene_destroy(&js);
    }
    /* a worker rebuilding a job from its fields gets the same hash only
     * with the same frame */
    char why[300];
    for (int frame = 0; frame < 3; frame++) {
        job_options o = seq->jobs[1]->options;
        o.frame = frame;
        job *w = job_new(seq->jobs[1]->scene_file, seq->jobs[1]->scene_text,
                         seq->jobs[1]->scene_len, &o);
        assert_true(job_finish(w, why, sizeof why));
        if (frame == 1) assert_string_equal(w->hash, seq->jobs[1]->hash);
        else assert_string_not_equal(w->hash, seq->jobs[1]->hash);
        if (frame == 0) assert_string_equal(w->hash, seq->jobs[0]->hash);
        job_destroy(&w);
    }
    frame_sequence_destroy(&seq);

    /* --frames 2,4 with -o: two jobs, the names from the pattern */
    seq = frame_sequence_load(path, NULL, "2,4", "o/x_%03d.exr", &usage, NULL, d);
    assert_non_null(seq);
    assert_int_equal(seq->count, 2);
    assert_string_equal(seq->outputs[0], "o/x_002.exr");
    assert_string_equal(seq->outputs[1], "o/x_004.exr");
    assert_null(seq->numbered);
    assert_int_equal(seq->jobs[1]->options.frame, 2);
    frame_sequence_destroy(&seq);
    assert_int_equal(sl_diag_error_count(d), 0);
    sl_diag_destroy(&d);

    /* a broken frame does not keep the others from rendering */
    path = write_rib("broken.rib", "Format 8 4 1\nProjection \"perspective\"\n"
                     "FrameBegin 1\nWorldBegin\nWorldEnd\nFrameEnd\n"
                     "FrameBegin 2\nWorldBegin\nSphere 1 -1 1 360\nWorldEnd\nFrameEnd\n");
    d = sl_diag_new();
    seq = frame_sequence_load(path, NULL, "2", "b.exr", &usage, NULL, d);
    assert_non_null(seq);
    assert_string_equal(seq->outputs[0], "b.0002.exr");
    frame_sequence_destroy(&seq);
    seq = frame_sequence_load(path, NULL, NULL, "b.exr", &usage, NULL, d);
    assert_null(seq);
    assert_false(usage);   /* the scene is at fault: exit 3 */
    assert_int_equal(sl_diag_error_count(d), 1);
    sl_diag_destroy(&d);

    /* no -o and no Display: a usage error naming -o */
    path = write_rib("nodisplay.rib", "Format 8 4 1\nProjection \"perspective\"\n"
                     "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n");
    d = sl_diag_new();
    seq = frame_sequence_load(path, NULL, NULL, NULL, &usage, NULL, d);
    assert_null(seq);
    assert_true(usage);
    assert_non_null(strstr(sl_diag_get(d, 0)->message, "needs -o OUT.exr: frame 1 has no "
                                                       "Display name"));
    sl_diag_destroy(&d);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/aafarm-test-frames-XXXXXX");
    if (!mkdtemp(dir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spec_parse),
        cmocka_unit_test(test_choose),
        cmocka_unit_test(test_output_names),
        cmocka_unit_test(test_one_job_per_frame),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) rc = rc ? rc : 1;
    return rc;
}
