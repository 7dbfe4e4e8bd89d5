/* Scenes on a 3D mesh (mesh.type box, ellipsoid):
 *  - a box scene with spheres loads: dimension 3, the cells' z, the box's
 *    z0, z1, nz; so does an ellipsoid scene (semi_z);
 *  - an ellipsoid without semi_z, with semi_z <= 0 or refinements > 7, a
 *    semi_z on the 2D ellipse, a sphere poking out of the ellipsoid or
 *    centred outside it, a cell without z: refused naming the key;
 *  - bad 3D input is refused as bad input (SP_ERR_INPUT) with a message
 *    naming the key: z1 <= z0, a cell without z, a sphere poking out of
 *    the box, a z on a 2D mesh, a PNG label image (initial.from is 3D
 *    too: test_initial_3d); pictures and checkpoints load;
 *    the shape term loads with its three moduli (shape.delta3 too), and
 *    a 2D scene's shape.delta3 is refused;
 *  - divisions load in 3D (phase 2) with any layout.support, and so do
 *    local supports (explicit, or auto with 5 cells or with divisions that
 *    can make more than 4), as in 2D;
 *  - `softpack run` of such a scene (initial.from a missing file, a 2D
 *    one with shape.delta3, ...) exits 2, names the key and writes
 *    nothing. */
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "command.h"
#include "public/error.h"
#include "scene/scene.h"

static const char good_mesh[] =
    "mesh: {type: box, x0: 0, y0: 0, z0: -0.1, x1: 0.6, y1: 0.5, z1: 0.4, nx: 6, ny: 5, nz: 5}\n";
static const char good_output[] = "output: {pictures: false}\n";
static const char good_cells[] =
    "cells:\n"
    "  - {x: 0.3, y: 0.25, z: 0.15, radius: 0.1}\n";

/* The good scene with @p extra appended (more cells, or sections; an
 * output section replaces the good one), its mesh line @p mesh if given. */
static int load(const char *mesh, const char *extra, sp_scene **out) {
  char text[2048];
  snprintf(text, sizeof text, "%s%s%s%s", mesh ? mesh : good_mesh,
           strstr(extra, "output:") ? "" : good_output, good_cells, extra);
  return sp_scene_load_text("bad3d.yaml", text, strlen(text), 0, NULL, out);
}

static void refused(const char *mesh, const char *extra, const char *key, const char *also) {
  sp_scene *scene = NULL;
  const int rc = load(mesh, extra, &scene);
  const char *msg = sp_error_message();
  printf("refused: %s\n", msg);
  CHECK(rc == SP_ERR_INPUT && !scene, "accepted (rc %d) with %s%s", rc, mesh ? mesh : "", extra);
  CHECK(strstr(msg, key) != NULL, "the message does not name %s: %s", key, msg);
  CHECK(!also || strstr(msg, also) != NULL, "the message does not say '%s': %s", also, msg);
  sp_scene_destroy(&scene);
}

/** `softpack ARGS` exits 2, its message names @p key (and says @p also),
 *  and test_scene_3d_out is not written. */
static void run_refused(const char *args, const char *key, const char *also) {
  char out[4096];
  struct stat st;
  const int status = run_softpack(args, out, sizeof out);
  printf("softpack %s: exit %d: %s", args, status, out);
  CHECK(status == 2, "exit status %d: %s", status, out);
  CHECK(strstr(out, key) && (!also || strstr(out, also)), "output: %s", out);
  CHECK(stat("test_scene_3d_out", &st) != 0, "test_scene_3d_out was written");
}

int main(void) {
  sp_scene *scene;
  CHECK_OK(load(NULL, "", &scene));
  CHECK(sp_scene_dim(scene) == 3 && scene->mesh.type == SP_MESH_BOX, "dimension %d",
        sp_scene_dim(scene));
  CHECK(scene->mesh.z0 == -0.1 && scene->mesh.z1 == 0.4 && scene->mesh.nz == 5,
        "box z: %g %g %d", scene->mesh.z0, scene->mesh.z1, scene->mesh.nz);
  CHECK(scene->cells[0].z == 0.15, "cells[0].z = %g", scene->cells[0].z);
  sp_scene_destroy(&scene);

  const char *box_low =
      "mesh: {type: box, x0: 0, y0: 0, z0: 0.4, x1: 0.6, y1: 0.5, z1: 0.4, nx: 6, ny: 5, nz: 5}\n";
  refused(box_low, "", "mesh.z1", NULL);
  const char *box = "mesh: {type: box, x1: 0.6, y1: 0.5, z0: -0.1, z1: 0.4, nz: 5}\n";
  refused(box, "  - {x: 0.3, y: 0.25, radius: 0.1}\n", "cells[1].z", "required");
  refused(box, "  - {x: 0.3, y: 0.25, z: 0.35, radius: 0.1}\n", "cells[1].radius", "sphere");
  refused(box, "  - {x: 0.3, y: 0.25, z: 0.5, radius: 0.1}\n", "cells[1].z", "outside");
  refused("mesh: {type: rectangle, x1: 0.6, y1: 0.5}\n", "", "cells[0].z", "3D mesh");
  const char *divides[] = {"division: {criterion: age}\nlayout: {support: full}\n",
                           "division: {criterion: mass, max_cells: 4}\n",
                           "division: {criterion: age}\n",
                           "division: {criterion: mass, max_cells: 5}\nlayout: {support: local}\n"};
  for (int i = 0; i < 4; ++i) {
    CHECK_OK(load(NULL, divides[i], &scene));
    CHECK(scene->division.criterion != SP_DIVIDE_NONE, "%s: no division", divides[i]);
    sp_scene_destroy(&scene);
  }
  /* the shape term in 3D: three moduli */
  CHECK_OK(load(NULL, "shape: {delta1: 1e4, delta2: 2e4, delta3: 3e4, scheme: implicit}\n"
                "time: {scheme: be}\n", &scene));
  CHECK(scene->shape.delta1 == 1e4 && scene->shape.delta2 == 2e4 && scene->shape.delta3 == 3e4 &&
            scene->shape.scheme == SP_SHAPE_IMPLICIT,
        "shape in 3D: %g %g %g", scene->shape.delta1, scene->shape.delta2, scene->shape.delta3);
  sp_scene_destroy(&scene);
  refused(NULL, "shape: {delta3: -1}\n", "shape.delta3", NULL);
  {
    const char *flat = "mesh: {type: rectangle, x1: 0.6, y1: 0.5}\n"
                       "output: {pictures: false}\n"
                       "cells:\n  - {x: 0.3, y: 0.25, radius: 0.1}\n"
                       "shape: {delta2: 1e5, delta3: 1e5}\n";
    sp_scene *s2 = NULL;
    const int rc = sp_scene_load_text("flat.yaml", flat, strlen(flat), 0, NULL, &s2);
    printf("refused: %s\n", sp_error_message());
    CHECK(rc == SP_ERR_INPUT && !s2, "2D scene with shape.delta3 accepted (rc %d)", rc);
    CHECK(strstr(sp_error_message(), "shape.delta3") &&
              strstr(sp_error_message(), "expected 0 on a 2D mesh"),
          "the message: %s", sp_error_message());
    sp_scene_destroy(&s2);
  }
  /* local supports, explicit or by auto with 5 cells */
  CHECK_OK(load(NULL, "layout: {support: local}\n", &scene));
  CHECK(scene->layout.support == SP_SUPPORT_LOCAL, "layout.support %d", scene->layout.support);
  sp_scene_destroy(&scene);
  CHECK_OK(load(NULL,
                "  - {x: 0.1, y: 0.1, z: 0.0, radius: 0.05}\n  - {x: 0.5, y: 0.1, z: 0.0, radius: 0.05}\n"
                "  - {x: 0.1, y: 0.4, z: 0.0, radius: 0.05}\n  - {x: 0.5, y: 0.4, z: 0.0, radius: 0.05}\n",
                &scene));
  CHECK(scene->n_cells == 5 && scene->layout.support == SP_SUPPORT_AUTO, "%d cells, support %d",
        scene->n_cells, scene->layout.support);
  sp_scene_destroy(&scene);
  /* pictures are 3D too (render_sections.c, render_surfaces.c) */
  CHECK_OK(load(NULL, "output: {pictures: true}\n", &scene));
  CHECK(scene->output.pictures == 1, "pictures %d", scene->output.pictures);
  sp_scene_destroy(&scene);
  /* checkpoints are 3D too */
  CHECK_OK(load(NULL, "output: {pictures: false, checkpoint_every: 5, checkpoint_seconds: 60}\n",
                &scene));
  CHECK(scene->output.checkpoint_every == 5, "checkpoint_every %d",
        scene->output.checkpoint_every);
  sp_scene_destroy(&scene);
  refused(NULL, "initial: {label_image: cells.png}\n", "initial.label_image",
          "initial.label_volume");

  /* the ellipsoid (mesh.type ellipsoid): semi_z required and > 0, only
   * there; its refinements at most 7; spheres inside it */
  const char *ellipsoid =
      "mesh: {type: ellipsoid, refinements: 2, semi_x: 0.8, semi_y: 0.6, semi_z: 0.5}\n";
  CHECK_OK(load(ellipsoid, "", &scene));
  CHECK(sp_scene_dim(scene) == 3 && scene->mesh.type == SP_MESH_ELLIPSOID &&
            scene->mesh.semi_z == 0.5,
        "ellipsoid: dimension %d, semi_z %g", sp_scene_dim(scene), scene->mesh.semi_z);
  sp_scene_destroy(&scene);
  refused("mesh: {type: ellipsoid, refinements: 2, semi_x: 0.5, semi_y: 0.3}\n", "",
          "mesh.semi_z", "required");
  refused("mesh: {type: ellipsoid, semi_x: 0.5, semi_y: 0.3, semi_z: 0}\n", "", "mesh.semi_z",
          "> 0");
  refused("mesh: {type: ellipsoid, semi_x: 0.5, semi_y: 0.3, semi_z: -0.2}\n", "",
          "mesh.semi_z", "> 0");
  refused("mesh: {type: ellipsoid, refinements: 8, semi_x: 0.5, semi_y: 0.3, semi_z: 0.3}\n", "",
          "mesh.refinements", "at most 7");
  refused("mesh: {type: ellipse, semi_z: 0.3}\n", "", "mesh.semi_z", "only with");
  refused(ellipsoid, "  - {x: 0.0, y: 0.0, z: 0.45, radius: 0.1}\n", "cells[1].radius",
          "ellipsoid");
  refused(ellipsoid, "  - {x: 0.0, y: 0.61, z: 0.0, radius: 0.01}\n", "cells[1].x", "outside");
  refused(ellipsoid, "  - {x: 0.0, y: 0.0, radius: 0.1}\n", "cells[1].z", "required");

  /* the program: exit 2, the key named, nothing written */
  FILE *f = fopen("test_scene_3d.yaml", "w");
  CHECK(f != NULL, "cannot write the scene");
  fprintf(f, "%s%sinitial: {from: run.h5}\n", good_mesh, good_output); /* (a missing file) */
  fclose(f);
  run_refused("run test_scene_3d.yaml --quiet --out test_scene_3d_out", "initial.from",
              "run.h5");
  /* a 2D scene's shape.delta3 by --set */
  run_refused("run " SP_SOURCE_DIR "/tests/scenes/rectangle_full.yaml --quiet --out "
              "test_scene_3d_out --set shape.delta3=1e5",
              "shape.delta3", "2D mesh");
  /* --set a picture width below its range: refused the same way */
  run_refused("run " SP_SOURCE_DIR "/tests/scenes/sphere_3d.yaml --quiet --out test_scene_3d_out "
              "--set output.pictures=true --set output.picture_width=10",
              "output.picture_width", NULL);
  /* an ellipsoid's semi_z set below 0 */
  run_refused("run " SP_SOURCE_DIR "/tests/scenes/two_spheres_ellipsoid.yaml --quiet --out "
              "test_scene_3d_out --set mesh.semi_z=-1",
              "mesh.semi_z", NULL);
  TEST_DONE();
}
