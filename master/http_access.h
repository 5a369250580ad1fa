/*
 * http_access.h: who may use the master's live monitor (--http,
 * docs/farm.md "Watching a render"): where it listens, and the token a
 * request must carry.
 *
 * The address: "PORT" (127.0.0.1), "HOST:PORT" with a numeric IPv4
 * address, "localhost" or "*" (every IPv4 interface), "[IPV6]:PORT"
 * ("[::]" every interface). Port 0 takes a free port, named in the
 * master's "monitor on http://..." line. A loopback address (127.0.0.0/8,
 * ::1) is reachable from this host alone; any other needs a token, as
 * --bind needs CURVE (main.c refuses it otherwise).
 *
 * The token: given with --http-token TOKEN or read from the first line of
 * --http-token-file FILE; 16 to 256 printable characters, no spaces. A
 * request carries it as "Authorization: Bearer TOKEN" or "?token=TOKEN";
 * it is compared in constant time. The page and its script carry no data
 * and are served to anyone; the API and the image need the token.
 */
#ifndef MASTER_HTTP_ACCESS_H
#define MASTER_HTTP_ACCESS_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/socket.h>

enum { HTTP_TOKEN_MIN = 16, HTTP_TOKEN_MAX = 256 };

typedef struct http_addr {
    struct sockaddr_storage sa;    /* the address to bind */
    socklen_t len;
    int family;                    /* AF_INET or AF_INET6 */
    int port;                      /* 0: any free port */
    bool loopback;                 /* reachable from this host only */
    char host[80];                 /* numeric, as in a URL ("127.0.0.1", "[::1]") */
} http_addr;

/* Parses an --http argument; false with a message naming it. */
bool http_addr_parse(const char *spec, http_addr *out, char *err, size_t errsz);

/* Checks a token's form (see above); false with a message. */
bool http_token_check(const char *token, char *err, size_t errsz);

/* Reads the token from the first line of path into buf (bufsz >
 * HTTP_TOKEN_MAX) and checks it; false with a message naming the file. */
bool http_token_read_file(const char *path, char *buf, size_t bufsz, char *err, size_t errsz);

/* A token option of a command line into buf (bufsz > HTTP_TOKEN_MAX):
 * from_file, the file `text` names (http_token_read_file), else `text`
 * itself, checked (http_token_check); false with a message. */
bool http_token_option(const char *text, bool from_file, char *buf, size_t bufsz, char *err,
                       size_t errsz);

/* Does given equal token? Constant time in the token's length; NULL
 * given: no. */
bool http_token_equal(const char *token, const char *given);

#endif
