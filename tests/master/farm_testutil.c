/*
 * farm_testutil.c: see farm_testutil.h.
 */
#include "farm_testutil.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "image/buffer.h"

const char *ft_master;
const char *ft_worker;

enum { MAX_CHILDREN = 64 };
static pid_t children[MAX_CHILDREN];

bool ft_init(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s AAFARM_MASTER AAFARM_WORKER\n", argv[0]);
        return false;
    }
    ft_master = argv[1];
    ft_worker = argv[2];
    signal(SIGPIPE, SIG_IGN);
    return true;
}

void ft_sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {}
}

double ft_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- files ---- */

char *ft_tempdir(void)
{
    char tmpl[] = "/tmp/aafarm-test-XXXXXX";
    char *dir = mkdtemp(tmpl);
    if (!dir) {
        perror("mkdtemp");
        abort();
    }
    return strdup(dir);
}

void ft_rmtree(const char *dir)
{
    if (getenv("AAFARM_TEST_KEEP")) {   /* for looking at the logs afterwards */
        fprintf(stderr, "kept %s\n", dir);
        return;
    }
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode)) ft_rmtree(path);
        else unlink(path);
    }
    closedir(d);
    rmdir(dir);
}

const char *ft_path(const char *dir, const char *name)
{
    static char ring[8][4096];
    static int next;
    char *buf = ring[next++ % 8];
    int n = snprintf(buf, sizeof ring[0], "%s/%s", dir, name);
    if (n < 0 || (size_t)n >= sizeof ring[0]) abort();
    return buf;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        perror(path);
        abort();
    }
}

static const char twave_sl[] =
    "/* the radial wave of Heidrich & Seidel, Figure 1 */\n"
    "displacement twave(float Km = 0.1; float frequency = 4; float decay = 2)\n"
    "{\n"
    "    float ds = s - 0.5, dt = t - 0.5;\n"
    "    float r = sqrt(ds * ds + dt * dt);\n"
    "    P += Km * exp(-decay * r) * sin(2 * PI * frequency * r) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char tmatte_sl[] =
    "surface tmatte(float Ka = 1; float Kd = 1)\n"
    "{\n"
    "    normal Nf = faceforward(normalize(N), I);\n"
    "    Oi = Os;\n"
    "    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf));\n"
    "}\n";

static const char spin_sl[] =
    "/* loops far beyond any instruction budget */\n"
    "displacement spin(float n = 1e9)\n"
    "{\n"
    "    float i, x = 0;\n"
    "    for (i = 0; i < n; i += 1) x += 1;\n"
    "    P += 0.01 * x * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char broken_sl[] =
    "displacement twave(float Km = 0.1)\n"
    "{\n"
    "    P += Km * * normalize(N);\n"
    "}\n";

static const char tnan_sl[] =
    "surface tnan()\n"
    "{\n"
    "    Oi = Os;\n"
    "    if (s > 0.5)\n"
    "        Ci = color(0 / 0, 1 / 0, -1 / 0);\n"
    "    else\n"
    "        Ci = Os * Cs;\n"
    "}\n";

static const char scene_rib[] =
    "# a small scene for the farm tests\n"
    "Option \"searchpath\" \"shader\" [\"shaders:&\"]\n"
    "Format 64 48 1\n"
    "PixelSamples 2 2\n"
    "Projection \"perspective\" \"fov\" [25]\n"
    "Translate 0 0.08 3.5\n"
    "Rotate -35 1 0 0\n"
    "WorldBegin\n"
    "  LightSource \"ambientlight\" 1 \"intensity\" [0.15]\n"
    "  LightSource \"distantlight\" 2 \"intensity\" [1.0] \"from\" [-1 2 -2] \"to\" [0 0 0]\n"
    "  AttributeBegin\n"
    "    Color [0.8 0.75 0.6]\n"
    "    Surface \"%s\"\n"
    "    Displacement \"%s\"\n"
    "    Sides 2\n"
    "    Polygon \"P\" [-1 0 -1  -1 0 1  1 0 1  1 0 -1]\n"
    "  AttributeEnd\n"
    "WorldEnd\n";

void ft_write_scene(const char *dir, ft_scene_kind kind)
{
    if (kind == FT_SCENE_NONE) return;
    char shaders[4096], rib[2048];
    snprintf(shaders, sizeof shaders, "%s/shaders", dir);
    mkdir(shaders, 0755);
    write_file(ft_path(shaders, "tmatte.sl"), tmatte_sl);
    const char *disp = "twave", *surf = "tmatte";
    if (kind == FT_SCENE_WAVE || kind == FT_SCENE_NAN)
        write_file(ft_path(shaders, "twave.sl"), twave_sl);
    if (kind == FT_SCENE_NAN) {
        write_file(ft_path(shaders, "tnan.sl"), tnan_sl);
        surf = "tnan";
    }
    if (kind == FT_SCENE_BROKEN) write_file(ft_path(shaders, "twave.sl"), broken_sl);
    if (kind == FT_SCENE_BUDGET) {
        write_file(ft_path(shaders, "spin.sl"), spin_sl);
        disp = "spin";
    }
    snprintf(rib, sizeof rib, scene_rib, surf, disp);
    write_file(ft_path(dir, "scene.rib"), rib);
}

char *ft_read(const char *path)
{
    FILE *f = fopen(path, "rb");
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    if (!buf) abort();
    if (f) {
        size_t got;
        while ((got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
            n += got;
            if (n + 1 == cap) {
                cap *= 2;
                buf = realloc(buf, cap);
                if (!buf) abort();
            }
        }
        fclose(f);
    }
    buf[n] = '\0';
    return buf;
}

long ft_position(const char *path, const char *needle)
{
    char *text = ft_read(path);
    const char *p = strstr(text, needle);
    long at = p ? (long)(p - text) : -1;
    free(text);
    return at;
}

int ft_count(const char *path, const char *needle)
{
    char *text = ft_read(path);
    int n = 0;
    for (const char *p = text; (p = strstr(p, needle)); p += strlen(needle)) n++;
    free(text);
    return n;
}

bool ft_wait_for(const char *path, const char *needle, int n, double timeout_s)
{
    for (double until = ft_now() + timeout_s;;) {
        if (ft_count(path, needle) >= n) return true;
        if (ft_now() > until) return false;
        ft_sleep_ms(20);
    }
}

long ft_json_number(const char *path, const char *key)
{
    char needle[128];
    snprintf(needle, sizeof needle, "\"%s\": ", key);
    char *text = ft_read(path);
    const char *p = strstr(text, needle);
    long v = p ? atol(p + strlen(needle)) : -1;
    free(text);
    return v;
}

bool ft_master_endpoint(const char *log, char *buf, size_t bufsz, double timeout_s)
{
    if (!ft_wait_for(log, "listening on ", 1, timeout_s)) return false;
    char *text = ft_read(log);
    const char *p = strstr(text, "listening on ") + strlen("listening on ");
    size_t len = strcspn(p, " \n");
    bool ok = len > 0 && len < bufsz;
    if (ok) {
        memcpy(buf, p, len);
        buf[len] = '\0';
    }
    free(text);
    return ok;
}

pid_t ft_start_master(const char *dir, const char *name, const char *tile, char *ep,
                      size_t epsz)
{
    char log[4096], out[4096], file[128];
    snprintf(file, sizeof file, "%s.log", name);
    snprintf(log, sizeof log, "%s", ft_path(dir, file));
    snprintf(file, sizeof file, "%s.exr", name);
    snprintf(out, sizeof out, "%s", ft_path(dir, file));
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out,
                          "--bind", "tcp://127.0.0.1:*", "--tile", tile, NULL};
    pid_t pid = ft_spawn(log, argv);
    return pid > 0 && ft_master_endpoint(log, ep, epsz, 30) ? pid : -1;
}

int ft_count_files(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strncmp(e->d_name, prefix, strlen(prefix)) == 0) n++;
    closedir(d);
    return n;
}

/* ---- processes ---- */

static void remember(pid_t pid)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] == 0) {
            children[i] = pid;
            return;
        }
}

static void forget(pid_t pid)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] == pid) children[i] = 0;
}

pid_t ft_spawn(const char *log, const char *const *argv)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        perror("fork");
        abort();
    }
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (fd >= 0) {
            dup2(fd, STDOUT_FILENO);
            dup2(fd, STDERR_FILENO);
            close(fd);
        }
        execv(argv[0], (char *const *)argv);
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    remember(pid);
    return pid;
}

int ft_wait(pid_t pid, double timeout_s)
{
    for (double until = ft_now() + timeout_s;;) {
        int status;
        pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) {
            forget(pid);
            if (WIFEXITED(status)) return WEXITSTATUS(status);
            if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
            return -1;
        }
        if (r < 0) return -1;
        if (ft_now() > until) return -1;
        ft_sleep_ms(10);
    }
}

bool ft_running(pid_t pid)
{
    siginfo_t info;
    memset(&info, 0, sizeof info);
    if (waitid(P_PID, (id_t)pid, &info, WEXITED | WNOHANG | WNOWAIT) != 0) return false;
    return info.si_pid == 0;   /* nothing to report: not exited */
}

void ft_stop_all(void)
{
    for (int i = 0; i < MAX_CHILDREN; i++) {
        if (children[i] <= 0) continue;
        kill(children[i], SIGCONT);
        kill(children[i], SIGKILL);
        waitpid(children[i], NULL, 0);
        children[i] = 0;
    }
}

/* Whether a loopback TCP port can be bound now (0: any, the kernel's
 * choice, returned in *got) */
static bool port_bindable(int port, int *got)
{
    int s = socket(AF_INET, SOCK_STREAM, 0);
    if (s < 0) return false;
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons((unsigned short)port);
    socklen_t len = sizeof a;
    bool ok = bind(s, (struct sockaddr *)&a, sizeof a) == 0 &&
              getsockname(s, (struct sockaddr *)&a, &len) == 0;
    if (ok && got) *got = ntohs(a.sin_port);
    close(s);
    return ok;
}

/* A free loopback port below the kernel's ephemeral range
 * (/proc/sys/net/ipv4/ip_local_port_range): a port from that range, free
 * when asked, can be handed to any program's next connect or listen
 * before the test's own process binds it (srun's I/O sockets took a
 * master's port so in CI: "Address already in use"); below it only an
 * explicit bind takes it. Random candidates, so that tests run side by
 * side rarely ask for the same one; the kernel's choice where none binds. */
int ft_free_port(void)
{
    int lo = 32768;
    FILE *f = fopen("/proc/sys/net/ipv4/ip_local_port_range", "r");
    if (f) {
        int a, b;
        if (fscanf(f, "%d %d", &a, &b) == 2 && a > 1024) lo = a;
        fclose(f);
    }
    static unsigned seed;
    if (!seed) seed = (unsigned)getpid() ^ (unsigned)time(NULL) * 2654435761u;
    const int base = 10000;
    for (int i = 0; lo > base + 1000 && i < 64; i++) {
        int port = base + (int)(rand_r(&seed) % (unsigned)(lo - base));
        if (port_bindable(port, NULL)) return port;
    }
    int port = -1;
    if (!port_bindable(0, &port)) return -1;
    return port;
}

/* ---- images ---- */

long ft_exr_diff(const char *a, const char *b)
{
    char err[512];
    image_buffer *ia = image_buffer_read_exr(a, err, sizeof err);
    if (!ia) {
        fprintf(stderr, "ft_exr_diff: %s\n", err);
        return -1;
    }
    image_buffer *ib = image_buffer_read_exr(b, err, sizeof err);
    if (!ib) {
        fprintf(stderr, "ft_exr_diff: %s\n", err);
        image_buffer_destroy(&ia);
        return -1;
    }
    image_diff diff;
    long n = -1;
    if (image_buffer_compare(ia, ib, 0.0, &diff, err, sizeof err)) {
        n = (long)diff.count;
        if (n) fprintf(stderr, "ft_exr_diff: %ld samples differ, largest %g in %s at (%d,%d)\n",
                       n, diff.max_abs, diff.channel, diff.x, diff.y);
    } else {
        fprintf(stderr, "ft_exr_diff: %s\n", err);
    }
    image_buffer_destroy(&ia);
    image_buffer_destroy(&ib);
    return n;
}

int ft_standalone(const char *dir, int tile)
{
    char t[16];
    snprintf(t, sizeof t, "%d", tile);
    const char *argv[] = {ft_worker, "--standalone", ft_path(dir, "scene.rib"), "-o",
                          ft_path(dir, "ref.exr"), "--tile", t, "--threads", "2", "-q", NULL};
    pid_t pid = ft_spawn(ft_path(dir, "standalone.log"), argv);
    int rc = ft_wait(pid, 120);
    if (rc != 0) {
        char *log = ft_read(ft_path(dir, "standalone.log"));
        fprintf(stderr, "the standalone reference render failed (exit %d):\n%s\n", rc, log);
        free(log);
    }
    return rc;
}

const char *ft_slow_worker(const char *dir, int delay_ms)
{
    const char *wrapper = ft_path(dir, "slow-worker.sh");
    FILE *f = fopen(wrapper, "w");
    if (!f) abort();
    fprintf(f, "#!/bin/sh\nexec '%s' --tile-delay %d \"$@\"\n", ft_worker, delay_ms);
    if (fclose(f) != 0 || chmod(wrapper, 0755) != 0) abort();
    return wrapper;
}

int ft_shv(const char *dir, const char *log, const char *fmt, va_list ap)
{
    char cmd[8192];
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    char wrapped[8400];
    snprintf(wrapped, sizeof wrapped, "exec timeout -k 2 120 /bin/sh -c '%s'", cmd);
    char path[4300];
    snprintf(path, sizeof path, "%s/%s", dir, log);
    const char *argv[] = {"/bin/sh", "-c", wrapped, NULL};
    return ft_wait(ft_spawn(path, argv), 130);
}

int ft_sh(const char *dir, const char *log, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = ft_shv(dir, log, fmt, ap);
    va_end(ap);
    return rc;
}

bool ft_program_dir(char *buf, size_t bufsz)
{
    char *real = realpath(ft_master, NULL);
    if (!real) return false;
    char *slash = strrchr(real, '/');
    int n = slash ? snprintf(buf, bufsz, "%.*s", (int)(slash - real), real) : -1;
    free(real);
    return n >= 0 && (size_t)n < bufsz;
}

/* ---- a test group's folder ---- */

static char **group_dir;

int ft_group_begin(char **dir_p, ft_scene_kind kind, int ref_tile)
{
    group_dir = dir_p;
    *dir_p = ft_tempdir();
    ft_write_scene(*dir_p, kind);
    return ref_tile > 0 && ft_standalone(*dir_p, ref_tile) != 0 ? -1 : 0;
}

int ft_group_teardown(void **state)
{
    (void)state;
    ft_stop_all();
    if (group_dir && *group_dir) {
        ft_rmtree(*group_dir);
        free(*group_dir);
        *group_dir = NULL;
    }
    return 0;
}

int ft_teardown(void **state)
{
    (void)state;
    ft_stop_all();
    return 0;
}
