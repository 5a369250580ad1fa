/*
 * tests/scene/test_scene_fuzz.c: the parser never crashes and always
 * answers cleanly, whatever the text. Valid RIB texts (the example scenes
 * and one text that uses every supported request) are mutated at random
 * (bytes replaced by RIB-significant characters or any byte, spans
 * deleted or duplicated, request names and brackets inserted, the text
 * cut short) a few thousand times with a fixed seed, and each mutant is
 * parsed. Checked for every mutant:
 *
 *   - the scene is returned exactly when no error was reported;
 *   - every diagnostic has a message, and a position inside the text
 *     (line 0 only for whole-file messages);
 *   - a returned scene is consistent: shader indices in range, a
 *     NULL-terminated search path, lights of objects in range.
 *
 * Run under AddressSanitizer (-DAAFARM_SANITIZE=ON) this is also the
 * memory-safety check. Argument: the scenes folder.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

static const char *scenes_dir = "scenes";

static const char every_request[] =
    "##RenderMan RIB\nversion 3.04\n"
    "Declare \"freq\" \"uniform float\"\n"
    "Option \"searchpath\" \"shader\" [\"shaders:&\"]\n"
    "Display \"x.exr\" \"file\" \"rgba\"\nFormat 64 32 1\nPixelSamples 2 2\n"
    "PixelFilter \"box\" 1 1\nExposure 1 2.2\nShadingRate 1\nClipping 0.1 100\n"
    "Projection \"perspective\" \"fov\" [40]\nScreenWindow -2 2 -1 1\n"
    "FrameBegin 1\nTranslate 0 0 5\nRotate -30 1 0 0\nScale 1 1 1\n"
    "ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]\n"
    "WorldBegin\n"
    "LightSource \"ambientlight\" 1 \"intensity\" 0.2\n"
    "LightSource \"spotlight\" 2 \"from\" [0 4 0] \"to\" [0 0 0] \"coneangle\" 0.5\n"
    "Attribute \"light\" \"shadows\" \"on\"\n"
    "LightSource \"pointlight\" \"p\" \"from\" [1 1 1] \"shadows\" \"off\"\n"
    "LightSource \"distantlight\" 4\nIlluminate 4 0\n"
    "CoordinateSystem \"lamp\"\n"
    "AttributeBegin\n"
    "  Attribute \"identifier\" \"name\" [\"a\"]\n"
    "  Attribute \"displacementbound\" \"sphere\" [0.2] \"coordinatesystem\" \"object\"\n"
    "  Color [1 0 0]\n  Opacity 1 1 1\n  Sides 1\n  Orientation \"inside\"\n"
    "  ReverseOrientation\n"
    "  Surface \"plastic\" \"Ks\" [0.5] \"color specularcolor\" [1 1 1] \"string t\" \"x\"\n"
    "  Displacement \"wave\" \"Km\" 0.1 \"freq\" [3]\n"
    "  TransformBegin\n    Translate 1 0 0\n    Sphere 1 -1 1 360\n  TransformEnd\n"
    "  Disk 0 1 360\n  Cylinder 1 -1 1 360\n  Cone 1 1 360\n  Torus 1 0.25 0 360 360\n"
    "  Hyperboloid 1 0 -1 0 1 1 360\n  Paraboloid 1 0 1 360\n"
    "  Polygon \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
    "  Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"
    "  PointsGeneralPolygons [2] [4 3] [0 1 2 3 4 5 6] \"P\" [0 0 0 4 0 0 4 4 0 0 4 0 "
    "1 1 0 2 1 0 1 2 0] \"facevarying float[2] st\" [0 0 1 0 1 1 0 1 0 0 1 0 0 1]\n"
    "  ObjectBegin 3\n  PointsPolygons [3 3] [0 1 2 0 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]"
    " \"vertex color Cs\" [1 0 0 0 1 0 0 0 1 1 1 1] \"uniform float foo\" [1 2]\n"
    "  ObjectEnd\n  ObjectInstance 3\n"
    "  Basis \"b-spline\" 1 \"catmull-rom\" 1\n"
    "  PatchMesh \"bicubic\" 4 \"periodic\" 4 \"nonperiodic\" \"P\" [0 0 0 1 0 0 2 0 1 3 0 0 "
    "0 1 0 1 1 1 2 1 1 3 1 0 0 2 0 1 2 1 2 2 1 3 2 0 0 3 0 1 3 0 2 3 1 3 3 0] "
    "\"vertex float h\" [0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15] \"varying float g\" [1 2 3 4 5 6 7 8]\n"
    "AttributeEnd\n"
    "CoordSysTransform \"lamp\"\nIdentity\nTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]\n"
    "Sphere 0.5 -0.5 0.5 180\n"
    "WorldEnd\nFrameEnd\nFrameBegin 2\nWorldBegin\nWorldEnd\nFrameEnd\n";

static const char *const inserts[] = {
    "AttributeBegin ", "AttributeEnd ", "TransformBegin ", "TransformEnd ", "WorldBegin ",
    "WorldEnd ", "FrameBegin ", "FrameEnd ", "Sphere ", "Polygon ", "Patch ", "Declare ",
    "LightSource ", "Illuminate ", "Surface ", "ObjectBegin ", "ObjectEnd ", "ObjectInstance ",
    "PointsPolygons ", "PatchMesh ", "Basis ", "[", "]", "\"", "\n", "#", " 1e308 ",
    " -0 ", " 1e-320 ", " \"P\" ", " \"uniform float[3] x\" ", " [ ] ", "\\", " nan ",
};

static uint64_t rng = 0x9E3779B97F4A7C15ull;

static uint64_t next_random(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

static size_t below(size_t n) { return n ? (size_t)(next_random() % n) : 0; }

typedef struct buffer { char *data; size_t len, cap; } buffer;

static void buf_splice(buffer *b, size_t at, size_t remove, const char *ins, size_t n)
{
    if (b->len - remove + n + 1 > b->cap) {
        b->cap = (b->len - remove + n + 1) * 2;
        b->data = realloc(b->data, b->cap);
    }
    memmove(b->data + at + n, b->data + at + remove, b->len - at - remove);
    memcpy(b->data + at, ins, n);
    b->len = b->len - remove + n;
    b->data[b->len] = '\0';
}

/* One random edit of the text. */
static void mutate(buffer *b)
{
    static const char significant[] = "[]\"#\n \t.-+eE0123456789abcXYZ\\";
    size_t at = below(b->len + 1);
    switch (below(6)) {
    case 0: {
        char c = significant[below(sizeof significant - 1)];
        buf_splice(b, at, at < b->len, &c, 1);
        break;
    }
    case 1: {
        char c = (char)below(256);
        buf_splice(b, at, at < b->len, &c, 1);
        break;
    }
    case 2:
        buf_splice(b, at, below(b->len - at + 1) % 40, "", 0);
        break;
    case 3: {
        size_t n = below(b->len - at + 1) % 60;
        char tmp[64];
        memcpy(tmp, b->data + at, n);
        buf_splice(b, at, 0, tmp, n);
        break;
    }
    case 4: {
        const char *s = inserts[below(sizeof inserts / sizeof inserts[0])];
        buf_splice(b, at, 0, s, strlen(s));
        break;
    }
    default:
        if (below(8) == 0)
            b->len = at, b->data[at] = '\0';
        break;
    }
}

/* Lines end in LF, CR-LF or a lone CR (rib_lexer.c). */
static int count_lines(const char *text, size_t len)
{
    int n = 1;
    for (size_t i = 0; i < len; i++)
        n += text[i] == '\n' || (text[i] == '\r' && (i + 1 == len || text[i + 1] != '\n'));
    return n;
}

/* The checks listed at the top, for one parse. */
static void check_answer(const buffer *b, scene *s, const sl_diag *d)
{
    assert_true((s != NULL) == (sl_diag_error_count(d) == 0));
    int lines = count_lines(b->data, b->len);
    for (size_t i = 0; i < sl_diag_count(d); i++) {
        const sl_diagnostic *x = sl_diag_get(d, i);
        assert_non_null(x->message);
        assert_true(x->message[0] != '\0');
        if (!x->file)
            continue;
        assert_true(x->line >= 0 && x->line <= lines);
        assert_true(x->line == 0 || x->col >= 1);
    }
    if (!s)
        return;
    assert_true(s->nobjects > 0);
    assert_null(s->search_path[s->nsearch_path]);
    for (int i = 0; i < s->nobjects; i++) {
        const scene_object *o = &s->objects[i];
        assert_true(o->attr->surface_shader >= -1 && o->attr->surface_shader < s->nshaders);
        assert_true(o->attr->displacement_shader >= -1 && o->attr->displacement_shader < s->nshaders);
        for (int k = 0; k < o->attr->nlights; k++)
            assert_true(o->attr->lights[k] >= 0 && o->attr->lights[k] < s->nlights);
    }
}

static int fuzz_text(const char *text, int rounds)
{
    buffer b = { NULL, 0, 0 };
    int parsed = 0;
    for (int r = 0; r < rounds; r++) {
        b.len = 0;
        buf_splice(&b, 0, 0, text, strlen(text));
        int edits = 1 + (int)below(8);
        for (int e = 0; e < edits; e++)
            mutate(&b);
        sl_diag *d = sl_diag_new();
        scene *s = scene_parse("fuzz.rib", b.data, b.len, d);
        check_answer(&b, s, d);
        parsed += s != NULL;
        scene_destroy(&s);
        sl_diag_destroy(&d);
    }
    free(b.data);
    return parsed;
}

static void test_valid_texts_parse(void **state)
{
    (void)state;
    sl_diag *d = sl_diag_new();
    scene *s = scene_parse("every.rib", every_request, strlen(every_request), d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    /* the first frame is read; the second is skipped, and counted */
    assert_int_equal(sl_diag_warning_count(d), 0);
    assert_int_equal(s->nframes, 2);
    /* 10 surfaces, a square with a triangular hole (7 triangles: one
     * mesh), an instance of two triangles (one mesh), a 4 x 1 b-spline
     * patch mesh */
    assert_int_equal(s->nobjects, 10 + 1 + 1 + 4);
    assert_int_equal(s->npieces, 10 + 7 + 2 + 4);
    assert_int_equal(s->nlights, 4);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_mutations(void **state)
{
    (void)state;
    static const char *const files[] = { "wave.rib", "nail.rib", "ufo.rib", "gallery.rib",
                                         "surfaces.rib" };
    int total = 0, parsed = fuzz_text(every_request, 3000);
    total += 3000;
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[1024];
        size_t len;
        snprintf(path, sizeof path, "%s/%s", scenes_dir, files[i]);
        char *text = read_whole_file(path, &len);
        assert_non_null(text);
        parsed += fuzz_text(text, 600);
        total += 600;
        free(text);
    }
    /* the mutations must exercise both outcomes */
    assert_true(parsed > 0);
    assert_true(parsed < total);
}

/* Texts of pure noise and degenerate shapes. */
static void test_noise(void **state)
{
    (void)state;
    static const char *const texts[] = {
        "", "\n\n\n", "#", "\"", "[", "]", "[[[[", "\"\\", "WorldBegin", "WorldEnd WorldEnd",
        "AttributeEnd AttributeEnd TransformEnd FrameEnd", "\xEF\xBB\xBF", "\x01\x02\x7f",
        "Declare", "Declare \"x\" \"\"", "Surface", "LightSource 1 2 3", "Polygon \"P\"",
        "Option \"searchpath\" \"shader\" [\"&:&:&::@\"]", "-", "+.", "1e", ".e1",
    };
    buffer b = { NULL, 0, 0 };
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        b.len = 0;
        buf_splice(&b, 0, 0, texts[i], strlen(texts[i]));
        sl_diag *d = sl_diag_new();
        scene *s = scene_parse("noise.rib", b.data, b.len, d);
        assert_null(s);
        check_answer(&b, s, d);
        sl_diag_destroy(&d);
    }
    /* random bytes */
    for (int r = 0; r < 200; r++) {
        b.len = 0;
        size_t n = below(300);
        for (size_t k = 0; k < n; k++) {
            char c = (char)below(256);
            buf_splice(&b, b.len, 0, &c, 1);
        }
        sl_diag *d = sl_diag_new();
        scene *s = scene_parse("noise.rib", b.data, b.len, d);
        check_answer(&b, s, d);
        scene_destroy(&s);
        sl_diag_destroy(&d);
    }
    free(b.data);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        scenes_dir = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_valid_texts_parse),
        cmocka_unit_test(test_mutations),
        cmocka_unit_test(test_noise),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
