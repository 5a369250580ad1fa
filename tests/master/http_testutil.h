/*
 * http_testutil.h: helpers of the live monitor's tests (test_farm_monitor,
 * test_monitor_browser): real HTTP requests with libcurl, the JSON parsed
 * with json-c, PNGs decoded with libpng, and the monitor's address from
 * the master's log.
 */
#ifndef TESTS_HTTP_TESTUTIL_H
#define TESTS_HTTP_TESTUTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <json-c/json.h>

/* One answer: its status (0: no answer), Content-Type and body. */
typedef struct ht_response {
    long status;
    char type[128];
    char *body;       /* NUL-terminated (malloc'd) */
    size_t len;
} ht_response;

/* GET (or `method`) url with an optional header line ("Authorization:
 * Bearer X", NULL: none); at most 20 s. */
ht_response ht_request(const char *method, const char *url, const char *header);
ht_response ht_get(const char *url);
/* `method` (POST) with body[0..len) (NULL: none) and an optional header. */
ht_response ht_post_body(const char *method, const char *url, const char *header,
                         const void *body, size_t len);
void ht_response_clear(ht_response *r);

/* The body parsed as JSON (json_object_put it), or NULL. */
json_object *ht_json(const ht_response *r);
/* Member lookups of a parsed document; abort the test when missing. */
json_object *ht_member(json_object *o, const char *key);
long ht_int(json_object *o, const char *key);

/* GETs base + path and parses it; NULL when not 200 or not JSON. */
json_object *ht_get_json(const char *base, const char *path);

/* Decodes a PNG to 8-bit RGB (malloc'd, 3 bytes a pixel); NULL when it
 * is not one. */
uint8_t *ht_png_rgb(const void *png, size_t len, int *width, int *height);

/* "http://127.0.0.1:PORT" from the master's "monitor on ..." line into
 * buf; false when it does not appear within timeout_s. */
bool ht_monitor_url(const char *log, char *buf, size_t bufsz, double timeout_s);

/* Polls /api/status until tiles.done >= min_done (and the job still
 * runs when running is set); the status then, or NULL after timeout_s. */
json_object *ht_wait_tiles(const char *base, long min_done, bool running, double timeout_s);

/* Polls /api/status until job.state is not "running"; that status or NULL. */
json_object *ht_wait_end(const char *base, double timeout_s);

#endif
