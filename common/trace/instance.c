/*
 * instance.c: which instances share their prototype's boxes (instance.h).
 *
 * A box of Heidrich & Seidel §3 is an OBJECT-space box of the displaced
 * surface over a (u,v) range, computed with the displacement shader run
 * in camera ("current") space. Two instances of one recorded surface have
 * the same base surface in object space; their displaced surfaces are the
 * same in object space when the displacement shader is equivariant under
 * the motion between their camera spaces: P + h N with h computed from
 * "shader" or "object" space points, s, t or u, v (every displacement
 * shader of scenes/), and the two transforms differing by a rigid motion
 * (a scale would change the length of the camera-space unit normal in
 * object units).
 *
 * That equivariance is not decided by analysing the shader: the instance's
 * surface is DEFINED as the prototype's displaced surface moved rigidly
 * (displace.c maps the prototype's points), so the prototype's boxes bound
 * it by construction and the guarantee holds whatever the shader does. The
 * test below only decides whether that definition is the one RenderMan
 * gives (the shader run on the instance itself): the motion must be rigid
 * (orientation kept), the shader instance the same, with no output
 * parameters (their values would be the prototype's), and on a 5 x 5 grid
 * of (u,v) (the cells' centres: an edge of the (u,v) square is often a
 * singular line, a sphere's pole, where a normal is a limit that the two
 * evaluations reach by different roundings) the instance's own displaced
 * points and normals must equal the prototype's moved ones within 1e-9 of
 * the coordinates (1e-7 for unit normals). A shader that reads camera-space P directly (noise(P)), or
 * the eye (I, E) or the per-object du, dv where they matter, fails the
 * grid and the instance keeps its own boxes, as before.
 */
#include "trace/instance.h"

#include <assert.h>
#include <math.h>

#include "trace/displace.h"

enum { PROBE = 5 };

static bool shader_allows(const sl_instance *inst)
{
    const sl_program *prog = sl_instance_program(inst);
    for (int i = 0; i < sl_program_param_count(prog); i++) {
        sl_param_info info;
        sl_program_param(prog, i, &info);
        if (info.output) return false;
    }
    return true;
}

/* The shader's named spaces move with the instance: "object" always does
 * (its to_camera), "shader" where the call's space is the instance's (a
 * Displacement inside ObjectBegin), "world", "camera", screen, NDC and
 * raster never do. (I and E do not either; sl_program_reads_global cannot
 * tell them from a transformed P, so the probe finds them.) A shader that names
 * one that does not is the instance's own surface wherever its use shows,
 * which the probe's grid may miss (fbm_filtered's shader-space noise
 * shows only near a sphere's poles): decided here from the program. */
static bool spaces_move(const trace_object *obj, const trace_object *proto)
{
    const sl_program *p = sl_instance_program(obj->displacement);
    static const int fixed[] = {SL_SPACE_WORLD, SL_SPACE_CAMERA, SL_SPACE_SCREEN, SL_SPACE_NDC,
                                SL_SPACE_RASTER};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        if (sl_program_uses_space(p, fixed[i])) return false;
    if (!sl_program_uses_space(p, SL_SPACE_SHADER)) return true;
    mat4 moved = mat4_mul(obj->from_proto, proto->displacement_spaces.to_current[SL_SPACE_SHADER]);
    const mat4 *own = &obj->displacement_spaces.to_current[SL_SPACE_SHADER];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            if (!(fabs(moved.m[r][c] - own->m[r][c]) <= 1e-9 * (1.0 + fabs(own->m[r][c]))))
                return false;
    return true;
}

static double vmax_abs(vec3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* The instance's own points against the prototype's moved ones at the
 * grid's cell centres (at least one must be on the surface). */
static bool same_surface(trace_thread *th, trace_object *obj, const trace_object *proto)
{
    int compared = 0;
    for (int j = 0; j < PROBE; j++)
        for (int i = 0; i < PROBE; i++) {
            double u = (i + 0.5) / PROBE, v = (j + 0.5) / PROBE;
            if (!geom_uv_inside(&obj->surf, u, v)) continue;
            trace_surface_point own, moved;
            obj->box_proto = NULL;
            trace_surface_point_eval(th, obj, u, v, &own);
            obj->box_proto = proto;
            trace_surface_point_eval(th, obj, u, v, &moved);
            if (th->failed) return false;
            double scale = 1.0 + fmax(vmax_abs(own.P), vmax_abs(moved.P));
            if (!(vmax_abs(v3_sub(own.P, moved.P)) <= 1e-9 * scale) ||
                !(vmax_abs(v3_sub(own.N, moved.N)) <= 1e-7))
                return false;
            compared++;
        }
    return compared > 0;
}

bool trace_instance_rigid(trace_object *obj, const trace_object *proto)
{
    if (proto->box_proto || !obj->displacement || obj->displacement != proto->displacement ||
        obj->flip != proto->flip || obj->surf.kind != proto->surf.kind ||
        !shader_allows(obj->displacement))
        return false;
    trace_instance_set_motion(obj, proto);
    return mat4_is_rotation(&obj->from_proto) && spaces_move(obj, proto);
}

void trace_instance_set_motion(trace_object *obj, const trace_object *proto)
{
    obj->from_proto = mat4_mul(obj->to_camera, proto->from_camera);
    obj->to_proto = mat4_mul(proto->to_camera, obj->from_camera);
}

bool trace_instance_moves(trace_thread *th, trace_object *obj, const trace_object *proto)
{
    assert(!obj->box_proto);
    bool moves = trace_instance_rigid(obj, proto) && same_surface(th, obj, proto);
    obj->box_proto = NULL;
    return moves;
}

int trace_instances_share(trace_thread *th, trace_world *world)
{
    int shared = 0;
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        const trace_object *proto = obj->box_proto;
        obj->box_proto = NULL;
        bool share = proto && proto->id < obj->id && trace_instance_moves(th, obj, proto);
        obj->box_proto = share ? proto : NULL;
        shared += share;
    }
    return shared;
}
