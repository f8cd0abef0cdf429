/* A small engine stand-in that uses the installed capture SDK: one crate (a rigid model) spinning
 * in front of a camera for 12 frames, with a point light. Usage: sdk_example CAPTURE_DIR.
 * tests/install/install_test.sh builds it against the installed SDK with pkg-config and with
 * CMake's find_package(dynbench), and checks what it writes with the installed dynbench. */
#include <math.h>
#include <stdio.h>

#include <dynbench/capture.h>

static int check(int status) {
  if (status != DBC_OK) fprintf(stderr, "sdk_example: %s\n", dbc_last_error());
  return status;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: sdk_example CAPTURE_DIR\n");
    return 2;
  }
  dbc_session* s = NULL;
  if (check(dbc_open(argv[1], "sdk_example 1.0", &s))) return 1;
  check(dbc_set_camera_settings(s, 16.0f / 9.0f, 60.0f, 0.1f, 1000.0f));
  const float positions[] = {-1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const uint32_t indices[] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
  dbc_mesh mesh = {0};
  mesh.mesh_id = 0;
  mesh.name = "crate";
  mesh.vertex_count = 4;
  mesh.positions = positions;
  mesh.triangle_count = 4;
  mesh.indices = indices;
  if (check(dbc_model_begin(s, "models/crate")) || check(dbc_model_mesh(s, &mesh)) || check(dbc_model_end(s))) return 1;
  const uint64_t camera = dbc_new_id(s), crate = dbc_new_id(s), light = dbc_new_id(s);
  for (uint64_t f = 0; f < 12; ++f) {
    const float angle = 0.1f * (float)f;
    const dbc_dual_quat pose = {0, sinf(angle / 2), 0, cosf(angle / 2), 0, 0, 0, 0};
    const float eye[3] = {0, 1, 5}, lamp[3] = {2, 3, 2}, white[3] = {1, 1, 1};
    if (check(dbc_frame_begin(s, f, (double)f / 60.0)) || check(dbc_camera(s, camera, eye, 0, 0, 0)) ||
        check(dbc_model(s, crate, "models/crate", pose)) || check(dbc_light(s, light, lamp, white, 0.0f, DBC_FALLOFF_LINEAR, DBC_LIGHT_POINT, 0, "none")) ||
        check(dbc_frame_end(s)))
      return 1;
  }
  return check(dbc_close(s)) ? 1 : 0;
}
