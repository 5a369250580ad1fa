/*
 * test_install.c: what a user installs (cmake/AafarmInstall.cmake,
 * docs/building.md "Installing"):
 *   - `cmake --install BUILD --prefix /opt/aafarm` with DESTDIR a scratch
 *     folder: the five programs (each answers --version), their manual
 *     pages, README and docs, the example scenes with their shaders and the
 *     launchers; the installed master renders the installed wave.rib from
 *     another folder, in an environment with nothing of the build tree in
 *     it, with the local workers it starts from beside itself: the EXR
 *     equals the build tree's standalone render of scenes/wave.rib;
 *   - `cpack -G DEB`: aafarm_VERSION_ARCH.deb, whose control (dpkg-deb -I)
 *     names the package, its version and Depends on libzmq5 and OpenEXR,
 *     whose contents (dpkg-deb -c) hold the programs, man pages and scenes;
 *     installed and removed by dpkg into a private root with its own
 *     database (--root: the system's is never touched), its Depends all
 *     installed on this system, and
 *     unpacked with dpkg -x into a scratch root (never installed into this
 *     system), the same checks and the same render. Skipped with one line
 *     where dpkg-deb is missing.
 *
 * Arguments: MASTER WORKER SOURCE_DIR BUILD_DIR CMAKE CPACK VERSION.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"

static char *dir;
static const char *src, *build, *cmake, *cpack, *version;

static const char *const programs[] = {"aafarm-master", "aafarm-worker", "aafarm-slc",
                                       "aafarm-maketx", "aafarm-keygen"};
enum { NPROGRAMS = sizeof programs / sizeof programs[0] };

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_NONE, 0) != 0) return -1;
    /* the reference: the build tree's worker on the repository's scene */
    return ft_sh(dir, "ref.log", "%s --standalone %s/scenes/wave.rib -o %s/ref.exr -q",
                 ft_worker, src, dir) == 0 ? 0 : -1;
}

static bool is_file(const char *path, bool executable)
{
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode)) {
        fprintf(stderr, "missing: %s\n", path);
        return false;
    }
    if (executable && !(st.st_mode & S_IXUSR)) {
        fprintf(stderr, "not executable: %s\n", path);
        return false;
    }
    return true;
}

static int count_in(const char *log, const char *needle)
{
    int n = ft_count(ft_path(dir, log), needle);
    if (n == 0) {
        char *text = ft_read(ft_path(dir, log));
        fprintf(stderr, "'%s' not in %s:\n%s\n", needle, log, text);
        free(text);
    }
    return n;
}

/* The installed tree under prefix (e.g. DESTDIR/opt/aafarm, ROOT/usr):
 * its files, every program's --version, and a render of the installed
 * wave.rib from the folder dir/cwd_name with an environment of nothing
 * but PATH=/usr/bin:/bin, equal to ref.exr. */
static void check_installed(const char *prefix, const char *cwd_name)
{
    char path[4600];
    for (int i = 0; i < NPROGRAMS; i++) {
        snprintf(path, sizeof path, "%s/bin/%s", prefix, programs[i]);
        assert_true(is_file(path, true));
        char log[64], expect[128];
        snprintf(log, sizeof log, "%s-%s.log", cwd_name, programs[i]);
        assert_int_equal(ft_sh(dir, log, "%s --version", path), 0);
        snprintf(expect, sizeof expect, "%s %s (commit ", programs[i], version);
        assert_int_equal(count_in(log, expect), 1);
        snprintf(path, sizeof path, "%s/share/man/man1/%s.1", prefix, programs[i]);
        assert_true(is_file(path, false));
    }
    const char *files[] = {"share/doc/aafarm/README.md", "share/doc/aafarm/docs/cluster.md",
                           "share/aafarm/scenes/wave.rib", "share/aafarm/scenes/shaders/wave.sl",
                           "share/aafarm/deploy/ssh/farm.sh",
                           "share/aafarm/deploy/systemd/aafarm-worker@.service"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", prefix, files[i]);
        assert_true(is_file(path, false));
    }
    /* the manual page is the program's own --help */
    snprintf(path, sizeof path, "%s/share/man/man1/aafarm-master.1", prefix);
    assert_true(ft_count(path, ".TH AAFARM\\-MASTER 1") == 1);
    assert_true(ft_count(path, "\\-\\-allow\\-keys DIR") >= 1);

    /* the render: another folder, another environment; no -o, so the
     * scene's Display name lands in that folder */
    char cwd[4300];
    snprintf(cwd, sizeof cwd, "%s/%s", dir, cwd_name);
    assert_int_equal(mkdir(cwd, 0755), 0);
    char log[64];
    snprintf(log, sizeof log, "%s-render.log", cwd_name);
    int rc = ft_sh(dir, log, "cd %s && exec env -i PATH=/usr/bin:/bin %s/bin/aafarm-master "
                   "%s/share/aafarm/scenes/wave.rib --local-workers 2", cwd, prefix, prefix);
    if (rc != 0) fprintf(stderr, "%s\n", ft_read(ft_path(dir, log)));
    assert_int_equal(rc, 0);
    snprintf(path, sizeof path, "%s/wave.exr", cwd);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), path), 0);
}

static void test_cmake_install_renders_from_anywhere(void **state)
{
    (void)state;
    int rc = ft_sh(dir, "install.log", "DESTDIR=%s/dest %s --install %s --prefix /opt/aafarm",
                   dir, cmake, build);
    if (rc != 0) fprintf(stderr, "%s\n", ft_read(ft_path(dir, "install.log")));
    assert_int_equal(rc, 0);
    char prefix[4300];
    snprintf(prefix, sizeof prefix, "%s/dest/opt/aafarm", dir);
    check_installed(prefix, "from-install");
    /* generated textures of a checkout are not shipped */
    snprintf(prefix, sizeof prefix, "%s/dest/opt/aafarm/share/aafarm/scenes/textures", dir);
    assert_int_equal(access(prefix, F_OK), -1);
}

static void test_debian_package_unpacks_and_renders(void **state)
{
    (void)state;
    if (ft_sh(dir, "which.log", "command -v dpkg-deb") != 0) {
        fprintf(stderr, "dpkg-deb not found (Debian package dpkg): the .deb is not checked\n");
        return;
    }
    int rc = ft_sh(dir, "cpack.log", "%s --config %s/CPackConfig.cmake -G DEB -B %s/deb",
                   cpack, build, dir);
    if (rc != 0) fprintf(stderr, "%s\n", ft_read(ft_path(dir, "cpack.log")));
    assert_int_equal(rc, 0);
    /* exactly one aafarm_VERSION_ARCH.deb, ARCH dpkg's */
    assert_int_equal(ft_sh(dir, "deb.log", "cd %s/deb && ls aafarm_%s_$(dpkg --print-architecture).deb",
                           dir, version), 0);
    char deb[4400];
    snprintf(deb, sizeof deb, "%s/deb/aafarm_%s_*.deb", dir, version);

    assert_int_equal(ft_sh(dir, "info.log", "dpkg-deb -I %s", deb), 0);
    assert_int_equal(count_in("info.log", " Package: aafarm\n"), 1);
    char line[128];
    snprintf(line, sizeof line, " Version: %s\n", version);
    assert_int_equal(count_in("info.log", line), 1);
    /* Depends, from dpkg-shlibdeps: Debian 12's names of the libraries */
    assert_int_equal(ft_sh(dir, "depends.log", "dpkg-deb -f %s Depends", deb), 0);
    const char *needs[] = {"libzmq5", "libopenexr-3-1-30", "libprotobuf-c1", "libpng16-16",
                           "libtiff6", "libc6"};
    for (size_t i = 0; i < sizeof needs / sizeof needs[0]; i++)
        assert_int_equal(count_in("depends.log", needs[i]), 1);

    assert_int_equal(ft_sh(dir, "contents.log", "dpkg-deb -c %s", deb), 0);
    for (int i = 0; i < NPROGRAMS; i++) {
        char want[128];
        snprintf(want, sizeof want, " ./usr/bin/%s\n", programs[i]);
        assert_int_equal(count_in("contents.log", want), 1);
        snprintf(want, sizeof want, " ./usr/share/man/man1/%s.1\n", programs[i]);
        assert_int_equal(count_in("contents.log", want), 1);
    }
    assert_int_equal(count_in("contents.log", " ./usr/share/aafarm/scenes/wave.rib\n"), 1);
    /* nothing outside /usr */
    assert_int_equal(ft_sh(dir, "outside.log", "dpkg-deb -c %s | grep -v \" \\./usr/\" "
                           "| grep -v \" \\./$\" && exit 1; exit 0", deb), 0);

    /* unpacked into a scratch root, never installed into this system */
    assert_int_equal(ft_sh(dir, "unpack.log", "dpkg -x %s %s/root", deb, dir), 0);
    char prefix[4300];
    snprintf(prefix, sizeof prefix, "%s/root/usr", dir);
    check_installed(prefix, "from-deb");

    /* installed by dpkg itself, into a private root with its own package
     * database (the system's is never touched): dpkg records it installed,
     * it renders from there, and dpkg removes every file it put */
    assert_int_equal(ft_sh(dir, "dpkg-i.log", "R=%s/dpkgroot && mkdir -p $R/var/lib/dpkg/info "
                           "$R/var/lib/dpkg/updates && touch $R/var/lib/dpkg/status && "
                           "dpkg --root=$R --force-not-root --force-depends --log=%s/dpkg.log "
                           "-i %s", dir, dir, deb), 0);
    assert_int_equal(ft_sh(dir, "dpkg-s.log", "dpkg --root=%s/dpkgroot -s aafarm", dir), 0);
    assert_int_equal(count_in("dpkg-s.log", "Status: install ok installed"), 1);
    snprintf(prefix, sizeof prefix, "%s/dpkgroot/usr", dir);
    check_installed(prefix, "dpkg-installed");
    /* --force-depends above only because the private database lists no
     * library: on this system every Depends is installed */
    assert_int_equal(ft_sh(dir, "deps-here.log", "dpkg-deb -f %s Depends | tr , \"\\n\" | "
                           "sed \"s/(.*//; s/|.*//; s/ //g\" | grep . | while read p; do "
                           "dpkg-query -W -f=\"\\${Status}\\n\" $p | grep -q \"install ok "
                           "installed\" || { echo \"$p not installed\"; exit 1; }; done", deb), 0);
    assert_int_equal(ft_sh(dir, "dpkg-r.log", "dpkg --root=%s/dpkgroot --force-not-root -r aafarm",
                           dir), 0);
    char gone[4400];
    snprintf(gone, sizeof gone, "%s/dpkgroot/usr/bin/aafarm-master", dir);
    assert_false(is_file(gone, true));
}

int main(int argc, char **argv)
{
    if (argc < 8 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: test_install MASTER WORKER SOURCE_DIR BUILD_DIR CMAKE CPACK VERSION\n");
        return 2;
    }
    src = argv[3];
    build = argv[4];
    cmake = argv[5];
    cpack = argv[6];
    version = argv[7];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_cmake_install_renders_from_anywhere, ft_teardown),
        cmocka_unit_test_teardown(test_debian_package_unpacks_and_renders, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
