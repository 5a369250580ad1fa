/*
 * scene.c: the scene model's own functions (see scene.h): freeing it, and
 * the queries the renderer and the master ask of it (an object's shaders,
 * a parameter by name, the file of a shader on the search path). Building
 * a scene is the RIB parser's job (rib_parser.c and the files it names).
 */
#include "scene/scene.h"
#include "sl/strbuf.h"
#ifdef SCENE_HAVE_GEOM
#include "geom/subdiv.h"
#include "geom/nurbs.h"
#include "util/xalloc.h"
#endif

#include <assert.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void scene_param_clear(scene_param *param)
{
    free(param->name);
    free(param->values);
    free(param->string);
    memset(param, 0, sizeof *param);
}

static void free_shader(scene_shader *sh)
{
    free(sh->name);
    for (int i = 0; i < sh->nparams; i++)
        scene_param_clear(&sh->params[i]);
    free(sh->params);
}

static void free_strings(char **list, int n)
{
    for (int i = 0; i < n; i++)
        free(list[i]);
    free(list);
}

void scene_destroy(scene **self_p)
{
    if (!self_p || !*self_p)
        return;
    scene *self = *self_p;
    for (int i = 0; i < self->nlights; i++)
        free(self->lights[i].handle);
    free(self->lights);
    free(self->objects);
    for (size_t i = 0; i < self->nkept; i++)
        free(self->kept[i]);
    free(self->kept);
    for (int i = 0; i < self->nshaders; i++)
        free_shader(&self->shaders[i]);
    free(self->shaders);
    for (int i = 0; i < self->nspaces; i++)
        free(self->spaces[i].name);
    free(self->spaces);
    free_strings(self->search_path, self->nsearch_path);
    free_strings(self->texture_path, self->ntexture_path);
    free_strings(self->shader_names, self->nshader_names);
#ifdef SCENE_HAVE_GEOM
    for (int i = 0; i < self->nsubdivs; i++)
        geom_subdiv_destroy(&self->subdivs[i]);
    for (int i = 0; i < self->nnurbs; i++)
        geom_nurbs_destroy(&self->nurbs[i]);
#endif
    free(self->subdivs);
    free(self->nurbs);
    for (int i = 0; i < self->nmeshes; i++)
        scene_mesh_destroy(&self->meshes[i]);
    free(self->meshes);
    free_strings(self->archives, self->narchives);
    free(self->display_name);
    free(self->display_type);
    free(self->display_mode);
    free(self->frame_numbers);
    free(self->file);
    free(self);
    *self_p = NULL;
}

void *scene_keep(scene *self, void *block)
{
    if (self->nkept == self->kept_cap) {
        self->kept_cap = self->kept_cap ? 2 * self->kept_cap : 64;
        self->kept = xreallocarray(self->kept, self->kept_cap, sizeof *self->kept);
    }
    self->kept[self->nkept++] = block;
    return block;
}

void scene_object_transforms(const scene *self, const scene_object *object, mat4 *to_camera,
                             mat4 *from_camera)
{
    *to_camera = mat4_mul(self->camera.camera_from_world, object->object_to_world);
    bool invertible = mat4_invert(to_camera, from_camera);
    assert(invertible);                /* rib_place_surface refused it otherwise */
    (void)invertible;
}

int scene_object_npieces(const scene_object *object)
{
    return object->mesh ? scene_mesh_npieces(object->mesh) : 1;
}

bool scene_object_piece(const scene_object *object, int k, geom_surface *s,
                        scene_primvar *vars, int *nvars)
{
    if (!object->mesh) {
        if (k != 0) return false;
        *s = *object->surface;
        if (object->nprimvars > 0)
            memcpy(vars, object->primvars, (size_t)object->nprimvars * sizeof *vars);
        *nvars = object->nprimvars;
        return true;
    }
    if (k < 0 || k >= scene_mesh_npieces(object->mesh)) return false;
    return scene_mesh_piece_surface(object->mesh, k, s, vars, nvars);
}

bool scene_object_piece_outline(const scene_object *object, int k, geom_surface *s)
{
    if (!object->mesh) {
        if (k != 0) return false;
        *s = *object->surface;
        return true;
    }
    if (k < 0 || k >= scene_mesh_npieces(object->mesh)) return false;
    return scene_mesh_piece_outline(object->mesh, k, s);
}

const scene_shader *scene_object_surface(const scene *self, const scene_object *object)
{
    int i = object->attr->surface_shader;
    return i >= 0 && i < self->nshaders ? &self->shaders[i] : NULL;
}

const scene_shader *scene_object_displacement(const scene *self, const scene_object *object)
{
    int i = object->attr->displacement_shader;
    return i >= 0 && i < self->nshaders ? &self->shaders[i] : NULL;
}

const scene_param *scene_shader_param(const scene_shader *shader, const char *name)
{
    for (int i = shader->nparams - 1; i >= 0; i--)
        if (strcmp(shader->params[i].name, name) == 0)
            return &shader->params[i];
    return NULL;
}

const char *const *scene_search_path(const scene *self)
{
    return (const char *const *)self->search_path;
}

static bool readable_on_disk(const char *path, void *arg)
{
    (void)arg;
    return access(path, R_OK) == 0;
}

char *scene_find_shader(const scene *self, const char *name,
                        scene_file_exists_fn exists, void *arg)
{
    if (!exists)
        exists = readable_on_disk;
    for (int i = 0; i < self->nsearch_path; i++) {
        const char *dir = self->search_path[i];
        bool here = strcmp(dir, ".") == 0;
        size_t n = strlen(dir) + strlen(name) + 5;
        char *path = xrealloc(NULL, n);
        if (here)
            snprintf(path, n, "%s.sl", name);
        else
            snprintf(path, n, "%s%s%s.sl", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", name);
        if (exists(path, arg))
            return path;
        free(path);
    }
    return NULL;
}

static bool same_string(const char *a, const char *b)
{
    return a == b || (a && b && strcmp(a, b) == 0);
}

bool scene_object_placeable(const scene_object *o, const scene_object *p)
{
    const scene_attributes *oa = o->attr, *pa = p->attr;
    return oa->displacement_shader == pa->displacement_shader && o->mesh == p->mesh &&
           o->surface == p->surface && oa->surface_shader == pa->surface_shader &&
           oa->sides == pa->sides && oa->nlights == pa->nlights &&
           (oa->lights == pa->lights ||
            memcmp(oa->lights, pa->lights, sizeof *oa->lights * (size_t)oa->nlights) == 0) &&
           o->primvars == p->primvars && o->nprimvars == p->nprimvars &&
           same_string(oa->name, pa->name);
}
