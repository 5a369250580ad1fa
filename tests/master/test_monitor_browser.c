/*
 * test_monitor_browser.c: the live monitor's page in a real browser
 * (headless Chromium, Debian's 'chromium'; issue 25). A master renders
 * with one local worker slowed by --tile-delay; once a third of the tiles
 * are in, Chromium loads the page with a virtual time budget (its
 * scripts run, fetch the API and the image, then the DOM is dumped):
 *   - the job is still running in the page's own words;
 *   - the worker table has a row for the worker (data-worker="local-1")
 *     with its name in it;
 *   - the image element loaded the frame's PNG (data-loaded="64x48") and
 *     the page counted rendered, non-black pixels in it
 *     (data-lit-pixels > 0);
 *   - a screenshot of the page is kept (argv[3], in the build folder).
 *
 * Where Chromium is missing or cannot start, the test says why and
 * exits 77, which CTest reports as skipped (SKIP_RETURN_CODE): never a
 * pass without a browser.
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
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"
#include "http_testutil.h"

enum { SKIP = 77 };

static char *dir;
static char chromium[1024];
static const char *screenshot;

/* chromium (or chromium-browser) on PATH; false when none. */
static bool find_chromium(void)
{
    const char *path = getenv("PATH");
    const char *names[] = {"chromium", "chromium-browser"};
    for (size_t k = 0; k < 2; k++) {
        for (const char *p = path ? path : "/usr/bin"; *p;) {
            size_t n = strcspn(p, ":");
            snprintf(chromium, sizeof chromium, "%.*s/%s", (int)n, p, names[k]);
            if (access(chromium, X_OK) == 0) return true;
            p += n + (p[n] == ':');
        }
    }
    return false;
}

/* Runs Chromium headless on url with `what` (--dump-dom or
 * --screenshot=FILE) and a virtual time budget, output to log; bounded by
 * timeout -k. Its exit status. */
static int run_chromium(const char *url, const char *what, const char *log)
{
    char profile[600], budget[64];
    snprintf(profile, sizeof profile, "--user-data-dir=%s", ft_path(dir, "chromium-profile"));
    snprintf(budget, sizeof budget, "--virtual-time-budget=%d", 4000);
    const char *argv[] = {"/usr/bin/timeout", "-k", "5", "60", chromium, "--headless",
                          "--no-sandbox", "--disable-gpu", "--no-first-run",
                          "--disable-dev-shm-usage", "--hide-scrollbars", profile,
                          "--window-size=1280,800", budget, what, url, NULL};
    return ft_wait(ft_spawn(log, argv), 90);
}

/* The number after `attr="` in text, -1 when missing. */
static long attr_number(const char *text, const char *attr)
{
    char needle[64];
    snprintf(needle, sizeof needle, "%s=\"", attr);
    const char *p = strstr(text, needle);
    return p ? strtol(p + strlen(needle), NULL, 10) : -1;
}

static void test_page_shows_the_render(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "master.log");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "out.exr"),
                          "--tile", "8", "--local-workers", "1", "--worker-binary",
                          ft_slow_worker(dir, 400), "--http", "127.0.0.1:0", NULL};
    pid_t m = ft_spawn(log, argv);
    char base[128], url[160];
    assert_true(ht_monitor_url(log, base, sizeof base, 30));
    json_object *st = ht_wait_tiles(base, 16, true, 60);   /* a third of 48 */
    assert_non_null(st);
    json_object_put(st);
    snprintf(url, sizeof url, "%s/", base);

    const char *dom_file = ft_path(dir, "dom.html");
    assert_int_equal(run_chromium(url, "--dump-dom", dom_file), 0);
    char *dom = ft_read(dom_file);
    const char *table = strstr(dom, "<table id=\"workers\">");
    assert_non_null(table);
    const char *row = strstr(table, "<tr class=\"alive\" data-worker=\"local-1\">");
    assert_non_null(row);
    assert_non_null(strstr(row, "local-1</td>"));
    assert_non_null(strstr(dom, "<span id=\"state\" class=\"state running\">running</span>"));
    const char *img = strstr(dom, "<img id=\"image\"");
    assert_non_null(img);
    assert_non_null(strstr(img, "data-loaded=\"64x48\""));
    long lit = attr_number(img, "data-lit-pixels");
    fprintf(stderr, "the page's image: %ld lit pixels of %d\n", lit, 64 * 48);
    assert_true(lit > 0);
    assert_true(lit < 64 * 48);   /* mid-render: not all of it */
    free(dom);

    char what[700];
    snprintf(what, sizeof what, "--screenshot=%s", screenshot);
    unlink(screenshot);
    assert_int_equal(run_chromium(url, what, ft_path(dir, "shot.log")), 0);
    char *png = ft_read(screenshot);
    struct stat sb;
    assert_int_equal(stat(screenshot, &sb), 0);
    int w = 0, h = 0;
    uint8_t *rgb = ht_png_rgb(png, (size_t)sb.st_size, &w, &h);
    assert_non_null(rgb);
    assert_int_equal(w, 1280);
    assert_int_equal(h, 800);
    fprintf(stderr, "screenshot kept: %s\n", screenshot);
    free(rgb);
    free(png);
    assert_int_equal(kill(m, SIGTERM), 0);
    assert_int_equal(ft_wait(m, 20), 130);
}

int main(int argc, char **argv)
{
    if (argc < 4 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: %s AAFARM_MASTER AAFARM_WORKER SCREENSHOT.png\n", argv[0]);
        return 2;
    }
    screenshot = argv[3];
    if (!find_chromium()) {
        fprintf(stderr, "test_monitor_browser: SKIPPED: no chromium on PATH (Debian package "
                "'chromium'; deploy/install-deps.sh installs it)\n");
        return SKIP;
    }
    dir = ft_tempdir();
    ft_write_scene(dir, FT_SCENE_WAVE);
    /* can this Chromium run here at all? a page of its own first */
    const char *probe = ft_path(dir, "probe.log");
    int rc = run_chromium("data:text/html,<p id=probe>chromium%20runs</p>", "--dump-dom", probe);
    char *text = ft_read(probe);
    bool runs = rc == 0 && strstr(text, "chromium runs");
    if (!runs) {
        size_t n = strlen(text);
        fprintf(stderr, "test_monitor_browser: SKIPPED: %s cannot run here (exit status %d); "
                "the end of its output:\n%s\n", chromium, rc, text + (n > 2000 ? n - 2000 : 0));
    }
    free(text);
    if (!runs) {
        ft_stop_all();
        ft_rmtree(dir);
        free(dir);
        return SKIP;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_page_shows_the_render),
    };
    rc = cmocka_run_group_tests(tests, NULL, NULL);
    ft_stop_all();
    ft_rmtree(dir);
    free(dir);
    return rc;
}
