// dynbench capture adapter, model half: included at the end of engine/rendermodel.cpp (by
// capture-hooks.patch), the one translation unit where the engine's model classes (animmodel,
// skelmodel, vertmodel) are complete. engine/dynbench_capture.cpp drives it once per frame through
// the functions declared in dynbench_capture.h.
//
// What is recorded: every model part the engine renders in a frame (players, their weapons,
// projectiles, gibs and debris, items), taken at animmodel::part::render where the engine has the
// part's world transform (its matrix stack) and, for skeletal models, the bone dual quaternions
// after animation blending (the skeleton's cache entry, skelmodel.h interpbones). Map models
// (ET_MAPMODEL entities) are recorded once as static models when the recording starts.
//
// Space. The engine draws a part with world = M . S(scale) . T(translate) . skin(v): M the rigid
// matrix stack, then the model's uniform scale and the part's offset, then the bone transforms
// (bdata) applied to the bind-pose vertex v. The capture format has rigid dual quaternions only, so
// the scale and offset A = S . T move into the model: vertices are exported as A v, and every
// bone transform B as A B A^-1, which is rigid again (rotation R, translation s (p + t - R t)).
// Then world = M . skin'(A v) with skin' built from the conjugated transforms. Everything then goes
// through the same change of basis as the map, (x, y, z) -> (-x, z, -y) (dynbench_capture.cpp); as
// that is a reflection, a rotation quaternion (x, y, z, w) becomes (x, -z, y, w) and triangles swap
// two corners.
//
// Identity. The engine keeps no id for a rendered thing, so one is inferred: a part rendered for a
// game entity (players, their attachments) keeps its id while it is rendered in consecutive frames
// for the same entity; a part rendered without one (projectiles, gibs, items) takes the id of the
// nearest instance of the same part in the previous frame, within kDynbenchMaxStepUnits (dynbench_capture.h). The same thing
// rendered again in one frame (shadow, glare passes) is recorded once; water reflections, which
// draw the followed player's own body, are not recorded.
//
// Map models are recorded once as static models, except those with a skeletal animation of their
// own (ANIM_MAPMODEL), which are evaluated every recorded frame and recorded like any skinned model,
// owned by their map entity.
//
// Limits: vertex-animated models (MD2/MD3 with several frames) are exported in their first frame
// and move rigidly; the engine blends bones as dual quaternions, glTF skins blend matrices.

#include "dynbench/capture.h"
#include "dynbench_capture.h"

namespace dynbench_models {


struct PartInstance {
  animmodel::part *part;
  const dynent *owner;  // NULL for parts rendered without a game entity
  vec origin;           // world position of the part's origin (its translation; also for matching)
  quat rotation;        // world rotation (engine space)
  vector<dualquat> joints;  // model-space joint transforms after animation, conjugated by A
  vector<dualquat> bones;   // the engine's skinning transforms (bdata) as drawn, for verifyFrame
  matrix4 world;
  uint64_t id;
};

static vector<PartInstance *> current, previous, staticParts;
static bool exportingStatic = false;
// Map models with an animation of their own (a waving flag): recorded every frame as dynamic models
// owned by their map entity (a stable address for the whole match), not frozen in a static pose.
static vector<int> animatedMapEntities;                 // indices into entities::getents()
static const dynent *mapModelOwner = NULL;             // set while one of them is evaluated

static void clearList(vector<PartInstance *> &list) { list.deletecontents(); }

static void engineToCapture(const vec &v, float out[3]) {
  out[0] = -v.x;
  out[1] = v.z;
  out[2] = -v.y;
}

static dbc_dual_quat captureDualQuat(const quat &engineRotation, const vec &engineTranslation) {
  quat r(engineRotation.x, -engineRotation.z, engineRotation.y, engineRotation.w);
  r.normalize();
  float t[3];
  engineToCapture(engineTranslation, t);
  // d = 1/2 (t, 0) r (quaternion product).
  dbc_dual_quat q;
  q.rx = r.x; q.ry = r.y; q.rz = r.z; q.rw = r.w;
  q.dx = 0.5f * (r.w * t[0] + t[1] * r.z - t[2] * r.y);
  q.dy = 0.5f * (r.w * t[1] + t[2] * r.x - t[0] * r.z);
  q.dz = 0.5f * (r.w * t[2] + t[0] * r.y - t[1] * r.x);
  q.dw = -0.5f * (t[0] * r.x + t[1] * r.y + t[2] * r.z);
  return q;
}

// A B A^-1 for A = S(scale) T(offset) and a rigid B = (R, p): (R, s (p + t - R t)).
static dualquat conjugateByPartScale(const dualquat &b, float scale, const vec &offset) {
  vec p = b.gettranslation();
  vec rotatedOffset = b.real.rotate(offset);
  vec translation = vec(p).add(offset).sub(rotatedOffset).mul(scale);
  return dualquat(b.real, translation);
}

static dbc_dual_quat captureBone(const dualquat &b) { return captureDualQuat(b.real, b.gettranslation()); }

static bool isSkeletal(const animmodel::part *p) {
  const int type = p->model->type();
  return type == MDL_MD5 || type == MDL_SMD || type == MDL_IQM;
}

static void capturePath(const animmodel::part *p, char *out, size_t size) {
  animmodel *m = p->model;
  if (m->parts.length() > 1)
    nformatstring(out, size, "%s#%d", m->name, m->parts.find(const_cast<animmodel::part *>(p)));
  else
    nformatstring(out, size, "%s", m->name);
}

// A texture's file relative to the data root, without the engine's load options (<dds>, <ffmask:..>).
static const char *textureFile(const Texture *t) {
  if (!t || t == notexture || !t->name) return NULL;
  const char *file = t->name;
  while (*file == '<') {
    const char *end = strchr(file, '>');
    if (!end) break;
    file = end + 1;
  }
  return *file ? file : NULL;
}

struct MeshArrays {
  vector<float> positions, normals, uvs, weights;
  vector<uint16_t> joints;
  vector<uint32_t> indices;
};

static bool exportMesh(dbc_session *session, int meshId, const char *name, const animmodel::skin *skin, MeshArrays &a) {
  dbc_mesh m = {};
  m.mesh_id = meshId;
  m.name = name;
  m.texture = skin ? textureFile(skin->tex) : NULL;
  m.mask_texture = skin ? textureFile(skin->masks) : NULL;
  m.vertex_count = size_t(a.positions.length() / 3);
  m.positions = a.positions.getbuf();
  m.normals = a.normals.getbuf();
  m.uvs = a.uvs.getbuf();
  m.joints = a.joints.empty() ? NULL : a.joints.getbuf();
  m.weights = a.weights.empty() ? NULL : a.weights.getbuf();
  m.triangle_count = size_t(a.indices.length() / 3);
  m.indices = a.indices.getbuf();
  return dbc_model_mesh(session, &m) == DBC_OK;
}

static void addVertex(MeshArrays &a, const vec &pos, const vec &norm, const vec2 &tc, float scale, const vec &offset) {
  float p[3], n[3];
  engineToCapture(vec(pos).add(offset).mul(scale), p);
  engineToCapture(norm, n);
  loopk(3) { a.positions.add(p[k]); a.normals.add(n[k]); }
  a.uvs.add(tc.x);
  a.uvs.add(tc.y);
}

static void addTriangle(MeshArrays &a, const ushort vert[3]) {
  // The change of basis is a reflection: swap two corners to keep the faces' orientation.
  a.indices.add(vert[0]);
  a.indices.add(vert[2]);
  a.indices.add(vert[1]);
}

static bool exportSkeletal(dbc_session *session, animmodel::part *p) {
  skelmodel::skelmeshgroup *group = (skelmodel::skelmeshgroup *)p->meshes;
  skelmodel::skeleton *skel = group->skel;
  const float scale = p->model->scale;
  const vec &offset = p->translate;
  int meshId = 0;
  loopv(group->meshes) {
    skelmodel::skelmesh &mesh = *(skelmodel::skelmesh *)group->meshes[i];
    if (mesh.numtris <= 0 || mesh.numverts <= 0) continue;
    MeshArrays a;
    loopj(mesh.numverts) {
      const skelmodel::vert &v = mesh.verts[j];
      addVertex(a, v.pos, v.norm, v.tc, scale, offset);
      const skelmodel::blendcombo &c = group->blendcombos[v.blend];
      float sum = 0;
      loopk(4) sum += c.weights[k];
      loopk(4) {
        a.joints.add(c.weights[k] > 0 ? c.bones[k] : 0);
        a.weights.add(sum > 0 ? c.weights[k] : (k == 0 ? 1.0f : 0.0f));
      }
    }
    loopj(mesh.numtris) addTriangle(a, mesh.tris[j].vert);
    if (!exportMesh(session, meshId++, mesh.name, p->skins.inrange(i) ? &p->skins[i] : NULL, a)) return false;
  }
  loopi(skel->numbones) {
    const skelmodel::boneinfo &b = skel->bones[i];
    if (b.parent >= i) {
      fprintf(stderr, "dynbench capture: %s: bone %d has parent %d after it\n", p->model->name, i, b.parent);
      return false;
    }
    dualquat local = b.base;
    if (b.parent >= 0) local.mul(skel->bones[b.parent].invbase, b.base);
    const dbc_dual_quat bind = captureBone(conjugateByPartScale(local, scale, offset));
    const dbc_dual_quat inverseBind = captureBone(conjugateByPartScale(b.invbase, scale, offset));
    defformatstring(name, "%s", b.name ? b.name : "");
    if (!name[0]) formatstring(name, "bone%d", i);
    if (dbc_model_joint(session, i, name, b.parent, bind, inverseBind) != DBC_OK) return false;
  }
  return true;
}

static bool exportVertexModel(dbc_session *session, animmodel::part *p) {
  vertmodel::vertmeshgroup *group = (vertmodel::vertmeshgroup *)p->meshes;
  const float scale = p->model->scale;
  const vec &offset = p->translate;
  int meshId = 0;
  loopv(group->meshes) {
    vertmodel::vertmesh &mesh = *(vertmodel::vertmesh *)group->meshes[i];
    if (mesh.numtris <= 0 || mesh.numverts <= 0) continue;
    MeshArrays a;
    // The first animation frame (vertex-animated models move rigidly in the capture).
    loopj(mesh.numverts) addVertex(a, mesh.verts[j].pos, mesh.verts[j].norm, mesh.tcverts[j].tc, scale, offset);
    loopj(mesh.numtris) addTriangle(a, mesh.tris[j].vert);
    if (!exportMesh(session, meshId++, mesh.name, p->skins.inrange(i) ? &p->skins[i] : NULL, a)) return false;
  }
  return true;
}

static bool exportModel(dbc_session *session, animmodel::part *p) {
  string path;
  capturePath(p, path, sizeof(path));
  if (dbc_has_model(session, path)) return true;
  if (dbc_model_begin(session, path) != DBC_OK) return false;
  if (!(isSkeletal(p) ? exportSkeletal(session, p) : exportVertexModel(session, p))) return false;
  return dbc_model_end(session) == DBC_OK;
}

static bool isMapModel(const model *m) {
  loopv(mapmodels) if (mapmodels[i].m == m) return true;
  return false;
}

// A map model whose skeletal parts have an animation for ANIM_MAPMODEL (md5anim "mapmodel").
static bool hasMapModelAnimation(model *m) {
  // Every Cube 2 model format (md2, md3, md5, iqm, smd, obj) is an animmodel; the game builds without RTTI.
  animmodel *am = static_cast<animmodel *>(m);
  loopv(am->parts) {
    animmodel::part *p = am->parts[i];
    if (p->meshes && isSkeletal(p) && p->anims[0] && p->anims[0][ANIM_MAPMODEL & ANIM_INDEX].length() > 0) return true;
  }
  return false;
}

// The engine's own call for a map model entity (renderva.cpp rendermapmodel), without drawing:
// the part hook sees its transforms.
static void evaluateMapModel(extentity &e, model *m) {
  int anim = ANIM_MAPMODEL | ANIM_LOOP, basetime = 0;
  if (e.flags & EF_ANIM) entities::animatemapmodel(e, anim, basetime);
  m->render(anim | ANIM_NORENDER, basetime, 0, e.o, e.attr1, 0, NULL, NULL, vec(1, 1, 1), vec(0, 0, 1), 1);
}

// Model-space joint transforms of a skeletal part as it was just drawn: J = bdata . base per bone
// (bdata is the skinning transform, base the bind pose), found again in the skeleton's cache.
static void skeletalJoints(animmodel::part *p, const animmodel::animstate *as, float pitch, const vec &axis, const vec &forward,
                           dynent *d, vector<dualquat> &joints, vector<dualquat> &bones) {
  skelmodel::skelmeshgroup *group = (skelmodel::skelmeshgroup *)p->meshes;
  skelmodel::skeleton *skel = group->skel;
  const dualquat *bdata = NULL;
  if (skel->numframes) {
    // The same arguments as skelmeshgroup::render: a cache hit, the entry it drew with.
    ragdolldata *rdata = as->cur.anim & ANIM_RAGDOLL || !d || !d->ragdoll || d->ragdoll->skel != skel->ragdoll ? NULL : d->ragdoll;
    bdata = skel->checkskelcache(p, as, pitch, axis, forward, rdata).bdata;
  }
  const float scale = p->model->scale;
  const vec &offset = p->translate;
  if (bdata) loopi(skel->numinterpbones) bones.add(bdata[i]);
  vector<dualquat> modelSpace;
  loopi(skel->numbones) {
    const skelmodel::boneinfo &b = skel->bones[i];
    dualquat j;
    if (bdata && b.interpindex >= 0) j.mul(bdata[b.interpindex], b.base);
    else if (b.parent >= 0) {
      // A bone no vertex follows: it keeps its bind pose relative to its parent.
      dualquat local;
      local.mul(skel->bones[b.parent].invbase, b.base);
      j.mul(modelSpace[b.parent], local);
    } else j = b.base;
    modelSpace.add(j);
    joints.add(conjugateByPartScale(j, scale, offset));
  }
}

// A canonical order for the parts drawn in a frame: the engine batches models in an order that
// follows their addresses, which differ from run to run; ids and records follow this order instead.
static bool drawnBefore(const PartInstance *a, const PartInstance *b) {
  if (int c = strcmp(a->part->model->name, b->part->model->name)) return c < 0;
  const int pa = a->part->model->parts.find(a->part), pb = b->part->model->parts.find(b->part);
  if (pa != pb) return pa < pb;
  const unsigned sa = dynbench_capture_entity_seed(a->owner), sb = dynbench_capture_entity_seed(b->owner);
  if (sa != sb) return sa < sb;
  const float ka[7] = {a->origin.x, a->origin.y, a->origin.z, a->rotation.x, a->rotation.y, a->rotation.z, a->rotation.w};
  const float kb[7] = {b->origin.x, b->origin.y, b->origin.z, b->rotation.x, b->rotation.y, b->rotation.z, b->rotation.w};
  loopi(7) if (ka[i] != kb[i]) return ka[i] < kb[i];
  return false;
}

}  // namespace dynbench_models

void animmodel::dynbench_capture_part(part *p, const animstate *as, float pitch, const vec &axis, const vec &forward, dynent *d, int anim) {
  using namespace dynbench_models;
  if (!dynbench_capture_recording() || !p->meshes) return;
  if (!exportingStatic && !mapModelOwner) {
    if (anim & ANIM_NORENDER) return;  // not drawn (e.g. computed only for its tags)
    if (!d && isMapModel(p->model)) return;  // recorded once as a static model, or by its own pass when animated
    // A water reflection draws the world as seen from below the water, in third person
    // (isthirdperson() is true while reflecting): the followed player's own body, which the
    // first-person view leaves out, is drawn there and nowhere else. Everything else a reflection
    // draws, the main pass draws too (culling is off while capturing).
    if (reflecting) return;
  }
  const dynent *owner = d ? d : mapModelOwner;
  const matrix4 &world = matrixstack[matrixpos];
  const vec origin = world.gettranslation();
  vector<PartInstance *> &list = exportingStatic ? staticParts : current;
  // Drawn again this frame (shadow map, reflection, refraction): recorded once.
  loopv(list) {
    const PartInstance &other = *list[i];
    if (other.part == p && other.owner == owner && (owner || other.origin.dist(origin) < 1e-3f)) return;
  }
  PartInstance *instance = new PartInstance;
  instance->part = p;
  instance->owner = owner;
  instance->origin = origin;
  instance->rotation = quat(world);
  instance->rotation.normalize();
  instance->id = 0;
  instance->world = world;
  if (isSkeletal(p)) skeletalJoints(p, as, pitch, axis, forward, d, instance->joints, instance->bones);
  list.add(instance);
}

bool dynbench_models_capture_static(dbc_session *session) {
  using namespace dynbench_models;
  // Every map model entity as renderva.cpp's rendermapmodel draws it, without drawing: the part
  // hook sees its transforms.
  exportingStatic = true;
  const vector<extentity *> &ents = entities::getents();
  loopv(ents) {
    extentity &e = *ents[i];
    if (e.type != ET_MAPMODEL) continue;
    model *m = loadmapmodel(e.attr2);
    if (!m) continue;
    if (hasMapModelAnimation(m)) {
      animatedMapEntities.add(i);  // recorded every frame by dynbench_models_export
      continue;
    }
    evaluateMapModel(e, m);
  }
  exportingStatic = false;
  staticParts.sort(drawnBefore);
  loopv(staticParts) if (!exportModel(session, staticParts[i]->part)) return false;
  return true;
}

bool dynbench_models_export(dbc_session *session) {
  using namespace dynbench_models;
  const vector<extentity *> &ents = entities::getents();
  loopv(animatedMapEntities) {
    extentity &e = *ents[animatedMapEntities[i]];
    model *m = loadmapmodel(e.attr2);
    if (!m) continue;
    mapModelOwner = reinterpret_cast<const dynent *>(&e);
    evaluateMapModel(e, m);
    mapModelOwner = NULL;
  }
  current.sort(drawnBefore);
  loopv(current) if (!exportModel(session, current[i]->part)) return false;
  // Ids: the same entity's part in the previous frame, else the nearest unclaimed instance of the
  // same part without an entity.
  vector<bool> claimed;
  loopv(previous) claimed.add(false);
  loopv(current) {
    PartInstance &c = *current[i];
    int best = -1;
    float bestDistance = kDynbenchMaxStepUnits;
    loopvj(previous) {
      const PartInstance &p = *previous[j];
      if (claimed[j] || p.part != c.part || p.owner != c.owner) continue;
      if (c.owner) { best = j; break; }
      const float distance = p.origin.dist(c.origin);
      if (distance < bestDistance) { bestDistance = distance; best = j; }
    }
    if (best >= 0) {
      claimed[best] = true;
      c.id = previous[best]->id;
    } else c.id = dbc_new_id(session);
  }
  return true;
}

static bool writeInstance(dbc_session *session, const dynbench_models::PartInstance &instance, bool isStatic) {
  using namespace dynbench_models;
  string path;
  capturePath(instance.part, path, sizeof(path));
  const dbc_dual_quat pose = captureDualQuat(instance.rotation, instance.origin);
  if (isStatic) return dbc_static_model(session, instance.id, path, pose) == DBC_OK;
  if (dbc_model(session, instance.id, path, pose) != DBC_OK) return false;
  if (instance.joints.empty()) return true;
  vector<dbc_dual_quat> joints;
  loopv(instance.joints) joints.add(captureBone(instance.joints[i]));
  return dbc_joints(session, instance.id, path, size_t(joints.length()), joints.getbuf()) == DBC_OK;
}

// The engine's own skinning of every skeletal part drawn this frame, as its vertex shader does it
// (dual quaternions blended per vertex, then scale, offset and the matrix stack), in capture space:
// lines `id mesh vertex x y z`. The Cube 2 test compares the converted dataset's skins with it.
bool dynbench_models_write_verification(const char *path) {
  using namespace dynbench_models;
  // stdio, not the engine's streams: those put written files under the game's home folder.
  FILE *out = fopen(path, "w");
  if (!out) return false;
  loopv(current) {
    const PartInstance &instance = *current[i];
    if (!isSkeletal(instance.part) || instance.bones.empty()) continue;
    skelmodel::skelmeshgroup *group = (skelmodel::skelmeshgroup *)instance.part->meshes;
    const float scale = instance.part->model->scale;
    int meshId = 0;
    loopvj(group->meshes) {
      skelmodel::skelmesh &mesh = *(skelmodel::skelmesh *)group->meshes[j];
      if (mesh.numtris <= 0 || mesh.numverts <= 0) continue;
      loopk(mesh.numverts) {
        const skelmodel::vert &v = mesh.verts[k];
        const skelmodel::blendcombo &c = group->blendcombos[v.blend];
        dualquat blended = instance.bones[c.interpbones[0]];
        blended.mul(c.weights[0]);
        for (int w = 1; w < 4 && c.weights[w]; ++w) blended.accumulate(instance.bones[c.interpbones[w]], c.weights[w]);
        blended.normalize();
        const vec skinned = blended.transform(v.pos);
        vec world;
        instance.world.transform(vec(skinned).add(instance.part->translate).mul(scale), world);
        float p[3];
        engineToCapture(world, p);
        fprintf(out, "%llu %d %d %.6f %.6f %.6f\n", (unsigned long long)instance.id, meshId, k, p[0], p[1], p[2]);
      }
      ++meshId;
    }
  }
  return fclose(out) == 0;
}

bool dynbench_models_write(dbc_session *session, bool firstFrame) {
  using namespace dynbench_models;
  if (firstFrame) loopv(staticParts) {
    staticParts[i]->id = dbc_new_id(session);
    if (!writeInstance(session, *staticParts[i], true)) return false;
  }
  loopv(current) if (!writeInstance(session, *current[i], false)) return false;
  return true;
}

void dynbench_models_next_frame(bool keepIds) {
  using namespace dynbench_models;
  clearList(previous);
  if (keepIds) {
    loopv(current) previous.add(current[i]);
    current.setsize(0);
  } else clearList(current);
}

int dynbench_models_count() { return dynbench_models::previous.length(); }

void dynbench_models_forget_owner(const void *entity) {
  using namespace dynbench_models;
  // A sentinel owner: matches no entity, and is not NULL (NULL owners match by distance).
  static const char gone = 0;
  loopv(previous) if (previous[i]->owner == entity) previous[i]->owner = reinterpret_cast<const dynent *>(&gone);
  loopv(current) if (current[i]->owner == entity) current[i]->owner = reinterpret_cast<const dynent *>(&gone);
}
