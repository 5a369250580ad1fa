/*
 * test_http_access.c: who may use the live monitor (master/http_access.h):
 * the --http address forms and which of them are loopback, their errors,
 * the token's form, the token file, and the comparison (a prefix, a
 * longer string, NULL are refused).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "http_access.h"
#include "util/err.h"

static void expect_addr(const char *spec, int family, const char *host, int port, bool loopback)
{
    http_addr a;
    char err[ERR_LEN] = "";
    assert_true(http_addr_parse(spec, &a, err, sizeof err));
    assert_int_equal(a.family, family);
    assert_string_equal(a.host, host);
    assert_int_equal(a.port, port);
    assert_int_equal(a.loopback, loopback);
    if (family == AF_INET)
        assert_int_equal(ntohs(((struct sockaddr_in *)&a.sa)->sin_port), port);
    else
        assert_int_equal(ntohs(((struct sockaddr_in6 *)&a.sa)->sin6_port), port);
}

static void test_address_forms(void **state)
{
    (void)state;
    expect_addr("8080", AF_INET, "127.0.0.1", 8080, true);
    expect_addr("0", AF_INET, "127.0.0.1", 0, true);
    expect_addr("127.0.0.1:9000", AF_INET, "127.0.0.1", 9000, true);
    expect_addr("127.1.2.3:9000", AF_INET, "127.1.2.3", 9000, true);
    expect_addr("localhost:80", AF_INET, "127.0.0.1", 80, true);
    expect_addr("0.0.0.0:8080", AF_INET, "0.0.0.0", 8080, false);
    expect_addr("*:8080", AF_INET, "0.0.0.0", 8080, false);
    expect_addr("192.168.1.20:65535", AF_INET, "192.168.1.20", 65535, false);
    expect_addr("[::1]:8080", AF_INET6, "[::1]", 8080, true);
    expect_addr("[::]:8080", AF_INET6, "[::]", 8080, false);
}

static void expect_error(const char *spec, const char *text)
{
    http_addr a;
    char err[ERR_LEN] = "";
    assert_false(http_addr_parse(spec, &a, err, sizeof err));
    assert_string_equal(err, text);
}

static void test_address_errors(void **state)
{
    (void)state;
    expect_error("65536", "--http 65536: the port must be a number 0..65535 (0: any free port), "
                 "got '65536'");
    expect_error("host:", "--http host:: the port must be a number 0..65535 (0: any free "
                 "port), got ''");
    expect_error("1.2.3.4:-1", "--http 1.2.3.4:-1: the port must be a number 0..65535 (0: any "
                 "free port), got '-1'");
    expect_error("example.org:80", "--http example.org:80: 'example.org' is not an address "
                 "this master can serve (give a numeric IPv4 address, localhost, *, or [IPv6] "
                 "before the port: 127.0.0.1:8080)");
    expect_error("[::g]:80", "--http [::g]:80: '::g' is not an IPv6 address");
}

static void test_token_form_and_compare(void **state)
{
    (void)state;
    char err[ERR_LEN];
    assert_true(http_token_check("abcdefghijklmnop", err, sizeof err));
    assert_false(http_token_check("abcdefghijklmno", err, sizeof err));
    assert_string_equal(err, "the monitor's token has 15 characters, it needs 16 to 256 (make "
                        "one with: head -c 24 /dev/urandom | base64)");
    assert_false(http_token_check("abcdefgh ijklmnop", err, sizeof err));
    assert_string_equal(err, "the monitor's token has a space, a control or a non-ASCII "
                        "character at position 9: printable ASCII only");
    const char *t = "0123456789abcdefXYZ";
    assert_true(http_token_equal(t, "0123456789abcdefXYZ"));
    assert_false(http_token_equal(t, "0123456789abcdefXY"));    /* a prefix */
    assert_false(http_token_equal(t, "0123456789abcdefXYZ1"));  /* longer */
    assert_false(http_token_equal(t, "0123456789abcdefXYz"));
    assert_false(http_token_equal(t, ""));
    assert_false(http_token_equal(t, NULL));
}

static void test_token_file(void **state)
{
    (void)state;
    char path[] = "/tmp/test_http_access_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "Zq8-token-from-a-file\r\nsecond line\n", 35), 35);
    close(fd);
    char buf[HTTP_TOKEN_MAX + 2], err[ERR_LEN];
    assert_true(http_token_read_file(path, buf, sizeof buf, err, sizeof err));
    assert_string_equal(buf, "Zq8-token-from-a-file");
    FILE *f = fopen(path, "w");
    fclose(f);   /* empty */
    assert_false(http_token_read_file(path, buf, sizeof buf, err, sizeof err));
    char want[ERR_LEN];
    snprintf(want, sizeof want, "--http-token-file %s:1: the file is empty: put the token on "
             "its first line", path);
    assert_string_equal(err, want);
    unlink(path);
    assert_false(http_token_read_file(path, buf, sizeof buf, err, sizeof err));
    snprintf(want, sizeof want, "--http-token-file %s: No such file or directory", path);
    assert_string_equal(err, want);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_address_forms),
        cmocka_unit_test(test_address_errors),
        cmocka_unit_test(test_token_form_and_compare),
        cmocka_unit_test(test_token_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
