/*
 * http_access.c: the monitor's address and token (see http_access.h).
 */
#include "http_access.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/err.h"

static bool parse_port(const char *text, const char *spec, int *port, char *err, size_t errsz)
{
    char *end = NULL;
    errno = 0;
    long n = strtol(text, &end, 10);
    if (!*text || *end || errno || n < 0 || n > 65535 || text[0] == '-' || text[0] == '+')
        return err_set(err, errsz, "--http %s: the port must be a number 0..65535 (0: any "
                       "free port), got '%s'", spec, text);
    *port = (int)n;
    return true;
}

bool http_addr_parse(const char *spec, http_addr *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    char host[64];
    const char *port_text;
    const char *colon = strrchr(spec, ':');
    if (!colon) {   /* a port alone: loopback */
        snprintf(host, sizeof host, "127.0.0.1");
        port_text = spec;
    } else {
        size_t n = (size_t)(colon - spec);
        if (n >= sizeof host)
            return err_set(err, errsz, "--http %s: the address is too long", spec);
        memcpy(host, spec, n);
        host[n] = '\0';
        port_text = colon + 1;
    }
    if (!parse_port(port_text, spec, &out->port, err, errsz)) return false;
    size_t hl = strlen(host);
    if (hl >= 2 && host[0] == '[' && host[hl - 1] == ']') {
        host[hl - 1] = '\0';
        struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)&out->sa;
        if (inet_pton(AF_INET6, host + 1, &a6->sin6_addr) != 1)
            return err_set(err, errsz, "--http %s: '%s' is not an IPv6 address", spec, host + 1);
        a6->sin6_family = AF_INET6;
        a6->sin6_port = htons((uint16_t)out->port);
        out->family = AF_INET6;
        out->len = sizeof *a6;
        out->loopback = IN6_IS_ADDR_LOOPBACK(&a6->sin6_addr);
        snprintf(out->host, sizeof out->host, "[%s]", host + 1);
        return true;
    }
    if (strcmp(host, "localhost") == 0) snprintf(host, sizeof host, "127.0.0.1");
    else if (strcmp(host, "*") == 0) snprintf(host, sizeof host, "0.0.0.0");
    struct sockaddr_in *a4 = (struct sockaddr_in *)&out->sa;
    if (inet_pton(AF_INET, host, &a4->sin_addr) != 1)
        return err_set(err, errsz, "--http %s: '%s' is not an address this master can serve "
                       "(give a numeric IPv4 address, localhost, *, or [IPv6] before the "
                       "port: 127.0.0.1:8080)", spec, host);
    a4->sin_family = AF_INET;
    a4->sin_port = htons((uint16_t)out->port);
    out->family = AF_INET;
    out->len = sizeof *a4;
    out->loopback = (ntohl(a4->sin_addr.s_addr) >> 24) == 127;
    snprintf(out->host, sizeof out->host, "%s", host);
    return true;
}

bool http_token_check(const char *token, char *err, size_t errsz)
{
    size_t n = strlen(token);
    if (n < HTTP_TOKEN_MIN || n > HTTP_TOKEN_MAX)
        return err_set(err, errsz, "the monitor's token has %zu characters, it needs %d to %d "
                       "(make one with: head -c 24 /dev/urandom | base64)", n, HTTP_TOKEN_MIN,
                       HTTP_TOKEN_MAX);
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)token[i];
        if (c <= 0x20 || c >= 0x7f)
            return err_set(err, errsz, "the monitor's token has a space, a control or a "
                           "non-ASCII character at position %zu: printable ASCII only", i + 1);
    }
    return true;
}

bool http_token_read_file(const char *path, char *buf, size_t bufsz, char *err, size_t errsz)
{
    FILE *in = fopen(path, "r");
    if (!in) return err_set(err, errsz, "--http-token-file %s: %s", path, strerror(errno));
    buf[0] = '\0';
    bool got = fgets(buf, (int)bufsz, in) != NULL;
    fclose(in);
    size_t n = strlen(buf);
    while (n > 0 && (buf[n - 1] == '\n' || buf[n - 1] == '\r')) buf[--n] = '\0';
    char why[ERR_LEN];
    if (!got || !http_token_check(buf, why, sizeof why)) {
        err_set(err, errsz, "--http-token-file %s:1: %s", path,
                got ? why : "the file is empty: put the token on its first line");
        memset(buf, 0, bufsz);
        return false;
    }
    return true;
}

bool http_token_option(const char *text, bool from_file, char *buf, size_t bufsz, char *err,
                       size_t errsz)
{
    if (from_file) return http_token_read_file(text, buf, bufsz, err, errsz);
    if (!http_token_check(text, err, errsz)) return false;
    snprintf(buf, bufsz, "%s", text);
    return true;
}

bool http_token_equal(const char *token, const char *given)
{
    if (!given) return false;
    size_t n = strlen(token), m = strlen(given);
    unsigned char diff = n != m;
    for (size_t i = 0; i < n; i++)
        diff |= (unsigned char)(token[i] ^ (i < m ? given[i] : 0));
    return diff == 0;
}
