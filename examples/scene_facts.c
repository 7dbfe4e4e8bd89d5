/*
 * scene_facts: a program built against an installed softpack. It loads a
 * scene with libsoftpack, as softpack run does, and prints its key facts:
 * the mesh it makes, the model, the time span, the solver and the cells.
 *
 *   scene_facts SCENE.yaml [section.key=value]...
 *
 * Exit status: 0 ok, 2 bad input (the library's message on stderr).
 */
#include <stdio.h>

#include <softpack/build_info.h>
#include <softpack/error.h>
#include <softpack/mesh.h>
#include <softpack/scene.h>

/** The scene's mesh: a rectangle, or the paper's five-patch ellipse. */
static int make_mesh(const sp_scene_mesh *m, sp_mesh **mesh) {
  if (m->type == SP_MESH_ELLIPSE)
    return sp_mesh_ellipse(m->refinements, m->semi_x, m->semi_y, m->buffer_layers,
                           m->buffer_width, mesh);
  return sp_mesh_rectangle(m->x0, m->y0, m->x1, m->y1, m->nx, m->ny, mesh);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: scene_facts SCENE.yaml [section.key=value]...\n");
    return 2;
  }
  sp_scene *scene = NULL;
  sp_mesh *mesh = NULL;
  int rc = sp_scene_load(argv[1], argc - 2, (const char *const *)argv + 2, &scene);
  if (rc == SP_OK) rc = make_mesh(&scene->mesh, &mesh);
  if (rc != SP_OK) {
    fprintf(stderr, "scene_facts: %s\n", sp_error_message());
    sp_scene_destroy(&scene);
    return sp_error_exit_status(rc);
  }
  printf("libsoftpack %s\n", sp_version());
  printf("mesh: %s, %d elements, %d nodes, h = %.4g, area of Omega %.6f\n",
         mesh->is_ellipse ? "ellipse" : "rectangle", mesh->n_elems, mesh->n_nodes, mesh->h,
         sp_mesh_region_area(mesh, SP_REGION_OMEGA));
  printf("model: alpha %g, kappa %g, lambda %g, mobility %g; interface width %.4g\n",
         scene->model.alpha, scene->model.kappa, scene->model.lambda, scene->model.mobility,
         sp_scene_interface_width(scene));
  printf("time: dt %g, t_end %g, at most %d steps\n", scene->time.dt, scene->time.t_end,
         scene->time.max_steps);
  printf("solver.linear: %s\n", sp_scene_linear_name(scene->solver.linear));
  printf("cells: %d\n", scene->n_cells);
  for (int k = 0; k < scene->n_cells; ++k)
    printf("  cell %d at (%g, %g), radius %g\n", k + 1, scene->cells[k].x, scene->cells[k].y,
           scene->cells[k].radius);
  sp_mesh_destroy(&mesh);
  sp_scene_destroy(&scene);
  return 0;
}
