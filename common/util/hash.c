/*
 * hash.c: SHA-256 written from the standard (NIST FIPS 180-4, "Secure
 * Hash Standard", 2015: §4.1.2 functions, §4.2.2 constants, §5.1.1
 * padding, §5.3.3 initial value, §6.2.2 the compression step), and the
 * canonical job hash built on it (the encoding is documented in hash.h).
 *
 * The farm uses SHA-256 to name jobs by their content, so collisions must
 * be out of reach even for a peer that crafts inputs: a cryptographic
 * hash, not a fast table hash.
 */
#include "util/hash.h"
#include "util/xalloc.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---------------------------------------------------------------------- */
/* SHA-256                                                                 */
/* ---------------------------------------------------------------------- */

/* FIPS 180-4 §4.2.2: the first 32 bits of the fractional parts of the
 * cube roots of the first 64 primes. */
static const uint32_t K[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1,
    0x923f82a4, 0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3,
    0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
    0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147,
    0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
    0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
    0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
    0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208,
    0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2,
};

/* FIPS 180-4 §5.3.3: the first 32 bits of the fractional parts of the
 * square roots of the first 8 primes. */
static const uint32_t H0[8] = {
    0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
    0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19,
};

static uint32_t rotr(uint32_t x, unsigned n) { return (x >> n) | (x << (32 - n)); }

/* FIPS 180-4 §4.1.2 */
static uint32_t ch(uint32_t x, uint32_t y, uint32_t z) { return (x & y) ^ (~x & z); }
static uint32_t maj(uint32_t x, uint32_t y, uint32_t z) { return (x & y) ^ (x & z) ^ (y & z); }
static uint32_t big_sigma0(uint32_t x) { return rotr(x, 2) ^ rotr(x, 13) ^ rotr(x, 22); }
static uint32_t big_sigma1(uint32_t x) { return rotr(x, 6) ^ rotr(x, 11) ^ rotr(x, 25); }
static uint32_t small_sigma0(uint32_t x) { return rotr(x, 7) ^ rotr(x, 18) ^ (x >> 3); }
static uint32_t small_sigma1(uint32_t x) { return rotr(x, 17) ^ rotr(x, 19) ^ (x >> 10); }

static uint32_t load_be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void store_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static void store_be64(uint8_t *p, uint64_t v)
{
    store_be32(p, (uint32_t)(v >> 32));
    store_be32(p + 4, (uint32_t)v);
}

/* FIPS 180-4 §6.2.2: one 512-bit block into the hash value. */
static void compress(uint32_t state[8], const uint8_t block[SHA256_BLOCK_SIZE])
{
    uint32_t w[64];
    for (int t = 0; t < 16; t++)
        w[t] = load_be32(block + 4 * t);
    for (int t = 16; t < 64; t++)
        w[t] = small_sigma1(w[t - 2]) + w[t - 7] + small_sigma0(w[t - 15]) + w[t - 16];

    uint32_t a = state[0], b = state[1], c = state[2], d = state[3];
    uint32_t e = state[4], f = state[5], g = state[6], h = state[7];
    for (int t = 0; t < 64; t++) {
        uint32_t t1 = h + big_sigma1(e) + ch(e, f, g) + K[t] + w[t];
        uint32_t t2 = big_sigma0(a) + maj(a, b, c);
        h = g;
        g = f;
        f = e;
        e = d + t1;
        d = c;
        c = b;
        b = a;
        a = t1 + t2;
    }
    state[0] += a;
    state[1] += b;
    state[2] += c;
    state[3] += d;
    state[4] += e;
    state[5] += f;
    state[6] += g;
    state[7] += h;
}

void sha256_init(sha256 *self)
{
    memcpy(self->state, H0, sizeof H0);
    self->length = 0;
    self->used = 0;
}

void sha256_update(sha256 *self, const void *data, size_t len)
{
    const uint8_t *p = data;
    if (len == 0)
        return;
    self->length += len;
    if (self->used > 0) {
        size_t take = SHA256_BLOCK_SIZE - self->used;
        if (take > len)
            take = len;
        memcpy(self->block + self->used, p, take);
        self->used += take;
        p += take;
        len -= take;
        if (self->used < SHA256_BLOCK_SIZE)
            return;
        compress(self->state, self->block);
        self->used = 0;
    }
    for (; len >= SHA256_BLOCK_SIZE; p += SHA256_BLOCK_SIZE, len -= SHA256_BLOCK_SIZE)
        compress(self->state, p);
    memcpy(self->block, p, len);
    self->used = len;
}

/* FIPS 180-4 §5.1.1: a 1 bit, zeros up to 56 mod 64 bytes, then the
 * message length in bits as a 64-bit big-endian number. */
void sha256_final(sha256 *self, uint8_t digest[SHA256_DIGEST_SIZE])
{
    uint64_t bits = self->length * 8;
    self->block[self->used++] = 0x80;
    if (self->used > 56) {
        memset(self->block + self->used, 0, SHA256_BLOCK_SIZE - self->used);
        compress(self->state, self->block);
        self->used = 0;
    }
    memset(self->block + self->used, 0, 56 - self->used);
    store_be64(self->block + 56, bits);
    compress(self->state, self->block);
    for (int i = 0; i < 8; i++)
        store_be32(digest + 4 * i, self->state[i]);
    memset(self, 0, sizeof *self);
}

void sha256_digest(const void *data, size_t len, uint8_t digest[SHA256_DIGEST_SIZE])
{
    sha256 ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, data, len);
    sha256_final(&ctx, digest);
}

void hash_hex(const uint8_t digest[SHA256_DIGEST_SIZE], char hex[HASH_HEX_SIZE])
{
    static const char digits[] = "0123456789abcdef";
    for (int i = 0; i < SHA256_DIGEST_SIZE; i++) {
        hex[2 * i] = digits[digest[i] >> 4];
        hex[2 * i + 1] = digits[digest[i] & 15];
    }
    hex[2 * SHA256_DIGEST_SIZE] = '\0';
}

bool hash_hex_valid(const char *s)
{
    if (!s)
        return false;
    for (int i = 0; i < 2 * SHA256_DIGEST_SIZE; i++) {
        bool digit = s[i] >= '0' && s[i] <= '9';
        bool lower = s[i] >= 'a' && s[i] <= 'f';
        if (!digit && !lower)
            return false;
    }
    return s[2 * SHA256_DIGEST_SIZE] == '\0';
}

/* ---------------------------------------------------------------------- */
/* the job hash (encoding: hash.h)                                         */
/* ---------------------------------------------------------------------- */

static void put_record(sha256 *ctx, char tag, const void *bytes, size_t len)
{
    uint8_t head[9];
    head[0] = (uint8_t)tag;
    store_be64(head + 1, (uint64_t)len);
    sha256_update(ctx, head, sizeof head);
    sha256_update(ctx, bytes, len);
}

static void put_string(sha256 *ctx, char tag, const char *s)
{
    put_record(ctx, tag, s, strlen(s));
}

static int by_shader_name(const void *a, const void *b)
{
    const hash_shader *x = *(const hash_shader *const *)a;
    const hash_shader *y = *(const hash_shader *const *)b;
    return strcmp(x->name, y->name);
}

static int by_option_key(const void *a, const void *b)
{
    const hash_option *x = *(const hash_option *const *)a;
    const hash_option *y = *(const hash_option *const *)b;
    return strcmp(x->key, y->key);
}

/* The shaders in name order as an array of pointers (free it), or NULL
 * when a field is missing or two names repeat. */
static const hash_shader **sorted_shaders(const hash_job_input *job)
{
    const hash_shader **v = xmalloc((job->shader_count + 1) * sizeof *v);
    for (size_t i = 0; i < job->shader_count; i++) {
        v[i] = &job->shaders[i];
        if (!v[i]->name || (!v[i]->text && v[i]->len > 0)) {
            free(v);
            return NULL;
        }
    }
    qsort(v, job->shader_count, sizeof *v, by_shader_name);
    for (size_t i = 1; i < job->shader_count; i++) {
        if (strcmp(v[i - 1]->name, v[i]->name) == 0) {
            free(v);
            return NULL;
        }
    }
    return v;
}

static const hash_option **sorted_options(const hash_job_input *job)
{
    const hash_option **v = xmalloc((job->option_count + 1) * sizeof *v);
    for (size_t i = 0; i < job->option_count; i++) {
        v[i] = &job->options[i];
        if (!v[i]->key || !v[i]->value) {
            free(v);
            return NULL;
        }
    }
    qsort(v, job->option_count, sizeof *v, by_option_key);
    for (size_t i = 1; i < job->option_count; i++) {
        if (strcmp(v[i - 1]->key, v[i]->key) == 0) {
            free(v);
            return NULL;
        }
    }
    return v;
}

int hash_job(const hash_job_input *job, char hex[HASH_HEX_SIZE])
{
    if (!job || !job->scene_name || (!job->scene_text && job->scene_len > 0) ||
        (!job->shaders && job->shader_count > 0) || (!job->options && job->option_count > 0))
        return -1;
    const hash_shader **shaders = sorted_shaders(job);
    const hash_option **options = shaders ? sorted_options(job) : NULL;
    if (!options) {
        free(shaders);
        return -1;
    }

    static const char domain[] = "aafarm-job-v1";
    sha256 ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, domain, sizeof domain - 1);
    put_string(&ctx, 'N', job->scene_name);
    put_record(&ctx, 'S', job->scene_text, job->scene_len);
    for (size_t i = 0; i < job->shader_count; i++) {
        put_string(&ctx, 'n', shaders[i]->name);
        put_record(&ctx, 't', shaders[i]->text, shaders[i]->len);
    }
    for (size_t i = 0; i < job->option_count; i++) {
        put_string(&ctx, 'k', options[i]->key);
        put_string(&ctx, 'v', options[i]->value);
    }
    free(shaders);
    free(options);

    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_final(&ctx, digest);
    hash_hex(digest, hex);
    return 0;
}

bool hash_fd(int fd, char hex[HASH_HEX_SIZE], uint64_t *len)
{
    enum { CHUNK = 1 << 20 };
    unsigned char *buf = xmalloc(CHUNK);
    sha256 h;
    sha256_init(&h);
    uint64_t off = 0;
    bool ok = true;
    for (;;) {
        ssize_t n = pread(fd, buf, CHUNK, (off_t)off);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) { ok = false; break; }
        if (n == 0) break;
        sha256_update(&h, buf, (size_t)n);
        off += (uint64_t)n;
    }
    free(buf);
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_final(&h, digest);
    hash_hex(digest, hex);
    if (len) *len = off;
    return ok;
}
