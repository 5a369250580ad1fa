/*
 * http_testutil.c: see http_testutil.h.
 */
#include "http_testutil.h"

#include <curl/curl.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "farm_testutil.h"

static size_t on_body(char *data, size_t size, size_t n, void *arg)
{
    ht_response *r = arg;
    size_t len = size * n;
    char *body = realloc(r->body, r->len + len + 1);
    if (!body) return 0;
    memcpy(body + r->len, data, len);
    r->len += len;
    body[r->len] = '\0';
    r->body = body;
    return len;
}

ht_response ht_request(const char *method, const char *url, const char *header)
{
    return ht_post_body(method, url, header, NULL, 0);
}

ht_response ht_post_body(const char *method, const char *url, const char *header,
                         const void *body, size_t len)
{
    ht_response r = {0};
    r.body = calloc(1, 1);
    CURL *c = curl_easy_init();
    if (!c) return r;
    struct curl_slist *headers = header ? curl_slist_append(NULL, header) : NULL;
    curl_easy_setopt(c, CURLOPT_URL, url);
    curl_easy_setopt(c, CURLOPT_CUSTOMREQUEST, method);
    if (strcmp(method, "HEAD") == 0) curl_easy_setopt(c, CURLOPT_NOBODY, 1L);
    curl_easy_setopt(c, CURLOPT_HTTPHEADER, headers);
    curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, on_body);
    curl_easy_setopt(c, CURLOPT_WRITEDATA, &r);
    curl_easy_setopt(c, CURLOPT_TIMEOUT, 20L);
    curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(c, CURLOPT_NOPROXY, "*");
    if (body) {
        headers = curl_slist_append(headers, "Expect:");
        curl_easy_setopt(c, CURLOPT_HTTPHEADER, headers);
        curl_easy_setopt(c, CURLOPT_POSTFIELDS, body);
        curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)len);
    }
    if (curl_easy_perform(c) == CURLE_OK) {
        curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &r.status);
        char *type = NULL;
        curl_easy_getinfo(c, CURLINFO_CONTENT_TYPE, &type);
        if (type) snprintf(r.type, sizeof r.type, "%s", type);
    }
    curl_slist_free_all(headers);
    curl_easy_cleanup(c);
    return r;
}

ht_response ht_get(const char *url)
{
    return ht_request("GET", url, NULL);
}

void ht_response_clear(ht_response *r)
{
    free(r->body);
    memset(r, 0, sizeof *r);
}

json_object *ht_json(const ht_response *r)
{
    if (!r->body) return NULL;
    json_tokener *tok = json_tokener_new();
    json_object *o = json_tokener_parse_ex(tok, r->body, (int)r->len);
    bool whole = o && json_tokener_get_error(tok) == json_tokener_success &&
                 (size_t)json_tokener_get_parse_end(tok) >= r->len - (r->len && r->body[r->len - 1] == '\n');
    json_tokener_free(tok);
    if (!whole) {
        if (o) json_object_put(o);
        fprintf(stderr, "not one JSON document: %.300s\n", r->body);
        return NULL;
    }
    return o;
}

json_object *ht_member(json_object *o, const char *key)
{
    json_object *v = NULL;
    if (!o || !json_object_object_get_ex(o, key, &v)) {
        fprintf(stderr, "JSON member '%s' missing\n", key);
        abort();
    }
    return v;
}

long ht_int(json_object *o, const char *key)
{
    return (long)json_object_get_int64(ht_member(o, key));
}

json_object *ht_get_json(const char *base, const char *path)
{
    char url[512];
    snprintf(url, sizeof url, "%s%s", base, path);
    ht_response r = ht_get(url);
    json_object *o = r.status == 200 ? ht_json(&r) : NULL;
    if (r.status != 200) fprintf(stderr, "GET %s: %ld %s\n", url, r.status, r.body);
    ht_response_clear(&r);
    return o;
}

uint8_t *ht_png_rgb(const void *png, size_t len, int *width, int *height)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, png, len)) return NULL;
    img.format = PNG_FORMAT_RGB;
    uint8_t *rgb = malloc(PNG_IMAGE_SIZE(img));
    if (!rgb || !png_image_finish_read(&img, NULL, rgb, 0, NULL)) {
        png_image_free(&img);
        free(rgb);
        return NULL;
    }
    *width = (int)img.width;
    *height = (int)img.height;
    return rgb;
}

bool ht_monitor_url(const char *log, char *buf, size_t bufsz, double timeout_s)
{
    const char *needle = "monitor on http://";
    if (!ft_wait_for(log, needle, 1, timeout_s)) return false;
    char *text = ft_read(log);
    const char *p = strstr(text, needle) + strlen("monitor on ");
    const char *slash = strchr(p + strlen("http://"), '/');   /* the path's */
    size_t n = slash ? (size_t)(slash - p) : strcspn(p, " \n");
    snprintf(buf, bufsz, "%.*s", (int)n, p);
    free(text);
    return true;
}

static json_object *wait_status(const char *base, long min_done, bool running, bool end,
                                double timeout_s)
{
    for (double until = ft_now() + timeout_s; ft_now() < until; ft_sleep_ms(50)) {
        json_object *st = ht_get_json(base, "/api/status");
        if (!st) continue;
        const char *state = json_object_get_string(ht_member(ht_member(st, "job"), "state"));
        bool runs = strcmp(state, "running") == 0;
        if (end ? !runs : ht_int(ht_member(st, "tiles"), "done") >= min_done) {
            if (end || !running || runs) return st;
        }
        json_object_put(st);
        if (!end && !runs) return NULL;   /* it ended before */
    }
    return NULL;
}

json_object *ht_wait_tiles(const char *base, long min_done, bool running, double timeout_s)
{
    return wait_status(base, min_done, running, false, timeout_s);
}

json_object *ht_wait_end(const char *base, double timeout_s)
{
    return wait_status(base, 0, false, true, timeout_s);
}
