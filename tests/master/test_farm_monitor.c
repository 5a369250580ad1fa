/*
 * test_farm_monitor.c: the master's live monitor (--http, issue 25) over
 * real HTTP (libcurl) on 127.0.0.1, with a real master and one local
 * worker slowed by --tile-delay so that the render is still running while
 * the test looks:
 *   - mid-render, /api/status parses and its counts agree with
 *     themselves (done + leased + queued = total, the tile letters, the
 *     worker of each tile done), /api/workers names the worker, and
 *     /api/image.png decodes to the image's size with rendered pixels;
 *     every tile the status called done before the image was fetched
 *     equals the final image there, every tile not done after it is
 *     black;
 *   - at the end (--http-linger keeps the monitor up) the status says
 *     done, every tile done by the worker, and the PNG is the same bytes
 *     as the --preview file; SIGTERM ends the linger with the render's
 *     exit status 0;
 *   - the page and its script are served, unknown paths get 404, other
 *     methods 405;
 *   - access: a network address without a token is refused before
 *     anything starts (exit 2, the reason); a bad token file too; with a
 *     token every /api/ request needs it (401 without or wrong, 200 as
 *     ?token= or Authorization: Bearer), the page does not.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "farm_testutil.h"
#include "http_testutil.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_WAVE, 0);
}

/* A master on 127.0.0.1:0 with one local worker taking delay_ms a tile,
 * tiles of 8 (48 of them); extra options after. Its base URL into base. */
static pid_t start_master(const char *name, int delay_ms, const char *const *extra, char *base,
                          size_t basesz)
{
    char out[64], preview[64], log[64];
    snprintf(out, sizeof out, "%s.exr", name);
    snprintf(preview, sizeof preview, "%s.png", name);
    snprintf(log, sizeof log, "%s.log", name);
    const char *argv[32] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, out),
                            "--preview", ft_path(dir, preview), "--tile", "8",
                            "--local-workers", "1", "--worker-binary",
                            ft_slow_worker(dir, delay_ms), "--http", "127.0.0.1:0"};
    int n = 14;
    for (int i = 0; extra && extra[i]; i++) argv[n++] = extra[i];
    argv[n] = NULL;
    pid_t m = ft_spawn(ft_path(dir, log), argv);
    assert_true(ht_monitor_url(ft_path(dir, log), base, basesz, 30));
    return m;
}

/* The tile letters of frame 0 (copied into buf) and its tile_worker. */
static json_object *frame0(json_object *st)
{
    return json_object_array_get_idx(ht_member(st, "frames"), 0);
}

static int count_letter(const char *s, char c)
{
    int n = 0;
    for (; *s; s++) n += *s == c;
    return n;
}

/* Is tile t of the grid (tiles of 8) equal in a and b / all black in a? */
static bool tile_equal(const uint8_t *a, const uint8_t *b, int w, int h, int tiles_x, int t,
                       bool black)
{
    int x0 = t % tiles_x * 8, y0 = t / tiles_x * 8;
    for (int y = y0; y < y0 + 8 && y < h; y++)
        for (int x = x0; x < x0 + 8 && x < w; x++)
            for (int c = 0; c < 3; c++) {
                size_t i = 3 * ((size_t)y * (size_t)w + (size_t)x) + (size_t)c;
                if (black ? a[i] != 0 : a[i] != b[i]) return false;
            }
    return true;
}

static void test_status_workers_and_image(void **state)
{
    (void)state;
    char base[128], url[256];
    const char *extra[] = {"--http-linger", "120", NULL};
    pid_t m = start_master("live", 250, extra, base, sizeof base);

    /* mid-render: half the tiles in, the job still running */
    json_object *st1 = ht_wait_tiles(base, 24, true, 60);
    assert_non_null(st1);
    snprintf(url, sizeof url, "%s/api/image.png", base);
    ht_response mid = ht_get(url);
    json_object *st2 = ht_get_json(base, "/api/status");
    json_object *wk = ht_get_json(base, "/api/workers");
    assert_non_null(st2);
    assert_non_null(wk);
    assert_int_equal(mid.status, 200);
    assert_string_equal(mid.type, "image/png");

    json_object *tiles = ht_member(st1, "tiles"), *f0 = frame0(st1);
    long total = ht_int(tiles, "total"), done = ht_int(tiles, "done");
    assert_int_equal(total, 48);
    assert_true(done >= 24 && done < total);
    assert_int_equal(done + ht_int(tiles, "leased") + ht_int(tiles, "queued"), total);
    assert_string_equal(json_object_get_string(ht_member(ht_member(st1, "job"), "state")),
                        "running");
    assert_int_equal(ht_int(f0, "width"), 64);
    assert_int_equal(ht_int(f0, "height"), 48);
    assert_int_equal(ht_int(f0, "tiles_x") * ht_int(f0, "tiles_y"), total);
    const char *letters = json_object_get_string(ht_member(f0, "tile_state"));
    assert_int_equal((long)strlen(letters), total);
    assert_int_equal(count_letter(letters, 'd'), done);
    assert_int_equal(count_letter(letters, 'l'), ht_int(tiles, "leased"));
    json_object *who = ht_member(f0, "tile_worker");
    for (int t = 0; t < total; t++)   /* done or leased: the worker's slot 0 */
        assert_int_equal(json_object_get_int(json_object_array_get_idx(who, (size_t)t)),
                         letters[t] == 'q' ? -1 : 0);
    assert_true(json_object_get_double(ht_member(st1, "rate_tiles_per_s")) > 0);
    assert_true(json_object_get_double(ht_member(st1, "eta_s")) > 0);
    assert_int_equal(ht_int(st1, "workers_alive"), 1);
    assert_true(json_object_array_length(ht_member(st1, "log")) >= 2);

    json_object *workers = ht_member(wk, "workers");
    assert_int_equal(json_object_array_length(workers), 1);
    json_object *w0 = json_object_array_get_idx(workers, 0);
    assert_string_equal(json_object_get_string(ht_member(w0, "name")), "local-1");
    assert_string_equal(json_object_get_string(ht_member(w0, "state")), "connected");
    assert_int_equal(ht_int(w0, "slot"), 0);
    assert_int_equal(ht_int(w0, "threads"), 1);
    assert_true(ht_int(w0, "tiles") >= done);
    assert_true(strlen(json_object_get_string(ht_member(w0, "host"))) > 0);

    int w = 0, h = 0;
    uint8_t *mid_rgb = ht_png_rgb(mid.body, mid.len, &w, &h);
    assert_non_null(mid_rgb);
    assert_int_equal(w, 64);
    assert_int_equal(h, 48);
    long lit = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++) lit += mid_rgb[i] != 0;
    assert_true(lit > 0);   /* rendered pixels, mid-render */

    /* the end: the monitor lingers; the status says done */
    json_object *end = ht_wait_end(base, 60);
    assert_non_null(end);
    assert_string_equal(json_object_get_string(ht_member(ht_member(end, "job"), "state")), "done");
    assert_int_equal(ht_int(ht_member(end, "tiles"), "done"), total);
    const char *all = json_object_get_string(ht_member(frame0(end), "tile_state"));
    assert_int_equal(count_letter(all, 'd'), total);
    assert_true(json_object_get_double(ht_member(end, "eta_s")) == 0);
    ht_response fin = ht_get(url);
    assert_int_equal(fin.status, 200);
    char *preview = ft_read(ft_path(dir, "live.png"));
    size_t plen = 0;
    {
        FILE *pf = fopen(ft_path(dir, "live.png"), "rb");
        assert_non_null(pf);
        fseek(pf, 0, SEEK_END);
        plen = (size_t)ftell(pf);
        fclose(pf);
    }
    assert_int_equal(fin.len, plen);   /* the same bytes as --preview */
    assert_memory_equal(fin.body, preview, plen);
    free(preview);
    int fw = 0, fh = 0;
    uint8_t *fin_rgb = ht_png_rgb(fin.body, fin.len, &fw, &fh);
    assert_non_null(fin_rgb);

    /* mid-render tiles agree with the statuses around the image */
    const char *before = letters;
    const char *after = json_object_get_string(ht_member(frame0(st2), "tile_state"));
    int tiles_x = (int)ht_int(f0, "tiles_x"), checked = 0;
    for (int t = 0; t < total; t++) {
        if (before[t] == 'd') {
            assert_true(tile_equal(mid_rgb, fin_rgb, w, h, tiles_x, t, false));
            checked++;
        } else if (after[t] != 'd') {
            assert_true(tile_equal(mid_rgb, fin_rgb, w, h, tiles_x, t, true));
            checked++;
        }
    }
    assert_true(checked >= 24);

    /* the page, its script, and what is not there */
    snprintf(url, sizeof url, "%s/", base);
    ht_response page = ht_get(url);
    assert_int_equal(page.status, 200);
    assert_non_null(strstr(page.type, "text/html"));
    assert_non_null(strstr(page.body, "<table id=\"workers\">"));
    assert_non_null(strstr(page.body, "<img id=\"image\""));
    snprintf(url, sizeof url, "%s/monitor.js", base);
    ht_response js = ht_get(url);
    assert_int_equal(js.status, 200);
    assert_non_null(strstr(js.body, "/api/image.png"));
    snprintf(url, sizeof url, "%s/etc/passwd", base);
    ht_response missing = ht_get(url);
    assert_int_equal(missing.status, 404);
    snprintf(url, sizeof url, "%s/api/image.png?frame=3", base);
    ht_response noframe = ht_get(url);
    assert_int_equal(noframe.status, 404);
    assert_non_null(strstr(noframe.body, "no frame 3"));
    snprintf(url, sizeof url, "%s/api/status", base);
    ht_response post = ht_request("POST", url, NULL);
    assert_int_equal(post.status, 405);

    /* SIGTERM ends the linger; the render's status stays 0 */
    assert_int_equal(kill(m, SIGTERM), 0);
    assert_int_equal(ft_wait(m, 20), 0);
    assert_int_equal(ft_count(ft_path(dir, "live.log"), "monitor stays up for 120 s"), 1);

    ht_response *all_r[] = {&mid, &fin, &page, &js, &missing, &noframe, &post};
    for (size_t i = 0; i < sizeof all_r / sizeof *all_r; i++) ht_response_clear(all_r[i]);
    free(mid_rgb);
    free(fin_rgb);
    json_object_put(st1);
    json_object_put(st2);
    json_object_put(wk);
    json_object_put(end);
}

static void test_network_address_needs_a_token(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "open.log");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "open.exr"),
                          "--http", "0.0.0.0:0", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, argv), 30), 2);
    assert_int_equal(ft_count(log, "aafarm-master: --http 0.0.0.0:0 is reachable from other "
                              "hosts, and without a token anyone there could watch the render "
                              "and take the image: give --http-token-file FILE"), 1);
    assert_int_equal(ft_count_files(dir, "open.exr"), 0);

    FILE *tf = fopen(ft_path(dir, "short.token"), "w");
    assert_non_null(tf);
    fputs("tooshort\n", tf);
    fclose(tf);
    const char *log2 = ft_path(dir, "short.log");
    const char *argv2[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "open.exr"),
                           "--http", "*:0", "--http-token-file", ft_path(dir, "short.token"), NULL};
    assert_int_equal(ft_wait(ft_spawn(log2, argv2), 30), 2);
    char needle[600];
    snprintf(needle, sizeof needle, "aafarm-master: --http-token-file %s:1: the monitor's token "
             "has 8 characters, it needs 16 to 256", ft_path(dir, "short.token"));
    assert_int_equal(ft_count(log2, needle), 1);

    const char *log3 = ft_path(dir, "bad.log");
    const char *argv3[] = {ft_master, ft_path(dir, "scene.rib"), "--http", "example.org:80", NULL};
    assert_int_equal(ft_wait(ft_spawn(log3, argv3), 30), 2);
    assert_int_equal(ft_count(log3, "aafarm-master: --http example.org:80: 'example.org' is not "
                              "an address this master can serve"), 1);
}

static void test_token_refused_and_accepted(void **state)
{
    (void)state;
    const char *token = "s3cret-Token-0123456789";
    FILE *tf = fopen(ft_path(dir, "monitor.token"), "w");
    assert_non_null(tf);
    fprintf(tf, "%s\n", token);
    fclose(tf);
    char base[128], url[512], header[256];
    /* the same check a network address gets, served on loopback only */
    const char *extra[] = {"--http-token-file", ft_path(dir, "monitor.token"), NULL};
    pid_t m = start_master("token", 300, extra, base, sizeof base);
    assert_int_equal(ft_count(ft_path(dir, "token.log"), "/ (token required)"), 1);
    const char *paths[] = {"/api/status", "/api/workers", "/api/image.png"};
    for (size_t i = 0; i < 3; i++) {
        snprintf(url, sizeof url, "%s%s", base, paths[i]);
        ht_response none = ht_get(url);
        assert_int_equal(none.status, 401);
        assert_non_null(strstr(none.body, "this monitor needs its token"));
        snprintf(url, sizeof url, "%s%s?token=%s", base, paths[i], "s3cret-Token-012345678X");
        ht_response wrong = ht_get(url);
        assert_int_equal(wrong.status, 401);
        snprintf(url, sizeof url, "%s%s?token=%s", base, paths[i], "s3cret-Token-01234567890");
        ht_response longer = ht_get(url);   /* the token and more */
        assert_int_equal(longer.status, 401);
        snprintf(url, sizeof url, "%s%s?token=%s", base, paths[i], token);
        ht_response query = ht_get(url);
        assert_int_equal(query.status, 200);
        snprintf(url, sizeof url, "%s%s", base, paths[i]);
        snprintf(header, sizeof header, "Authorization: Bearer %s", token);
        ht_response bearer = ht_request("GET", url, header);
        assert_int_equal(bearer.status, 200);
        ht_response *rs[] = {&none, &wrong, &longer, &query, &bearer};
        for (size_t k = 0; k < 5; k++) ht_response_clear(rs[k]);
    }
    snprintf(url, sizeof url, "%s/", base);   /* the page carries no data */
    ht_response page = ht_get(url);
    assert_int_equal(page.status, 200);
    ht_response_clear(&page);
    assert_int_equal(kill(m, SIGTERM), 0);
    assert_int_equal(ft_wait(m, 20), 130);   /* interrupted mid-render */
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_status_workers_and_image, ft_teardown),
        cmocka_unit_test_teardown(test_network_address_needs_a_token, ft_teardown),
        cmocka_unit_test_teardown(test_token_refused_and_accepted, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
