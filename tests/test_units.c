/* units.csv (output.length_unit, length_scale, time_unit, time_scale;
 * sp_output_units_write), no time stepping:
 * - with both units on a 2D mesh: one row per dimensional column of
 *   energy.csv, cells.csv, divisions.csv and contacts.csv with its unit and
 *   factor, exactly (a time x 4000 min, a mass = area x 50^2 um^2, a
 *   moment x 50^4 um^4, a contact length x 50 um);
 * - on a 3D mesh with the length alone: the 3D columns (zc, I3, volume),
 *   volumes x 50^3, surfaces x 50^2, no time rows;
 * - with neither unit: no file at all (the outputs are what they were). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "io/output.h"

static const char want_2d[] =
    "file,column,unit,scale\n"
    "energy.csv,t,min,4000\n"
    "energy.csv,dt,min,4000\n"
    "cells.csv,t,min,4000\n"
    "cells.csv,mass,um^2,2500\n"
    "cells.csv,xc,um,50\n"
    "cells.csv,yc,um,50\n"
    "cells.csv,I1,um^4,6250000\n"
    "cells.csv,I2,um^4,6250000\n"
    "cells.csv,core_mass,um^2,2500\n"
    "cells.csv,area,um^2,2500\n"
    "divisions.csv,t,min,4000\n"
    "divisions.csv,parent_mass_before,um^2,2500\n"
    "divisions.csv,parent_mass_after,um^2,2500\n"
    "divisions.csv,child_mass_after,um^2,2500\n"
    "contacts.csv,t,min,4000\n"
    "contacts.csv,contact,um,50\n"
    "contacts.csv,volume,um^2,2500\n"
    "contacts.csv,surface,um,50\n"
    "contacts.csv,free_surface,um,50\n";

static const char want_3d[] =
    "file,column,unit,scale\n"
    "cells.csv,mass,um^3,125000\n"
    "cells.csv,xc,um,50\n"
    "cells.csv,yc,um,50\n"
    "cells.csv,zc,um,50\n"
    "cells.csv,I1,um^5,312500000\n"
    "cells.csv,I2,um^5,312500000\n"
    "cells.csv,I3,um^5,312500000\n"
    "cells.csv,core_mass,um^3,125000\n"
    "cells.csv,volume,um^3,125000\n"
    "divisions.csv,parent_mass_before,um^3,125000\n"
    "divisions.csv,parent_mass_after,um^3,125000\n"
    "divisions.csv,child_mass_after,um^3,125000\n"
    "contacts.csv,contact,um^2,2500\n"
    "contacts.csv,volume,um^3,125000\n"
    "contacts.csv,surface,um^2,2500\n"
    "contacts.csv,free_surface,um^2,2500\n";

static char *read_all(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f) return NULL;
  static char text[8192];
  const size_t n = fread(text, 1, sizeof text - 1, f);
  text[n] = '\0';
  fclose(f);
  return text;
}

int main(void) {
  CHECK(system("rm -rf test_units_out && mkdir test_units_out") == 0, "cannot clear");
  const sp_output_units both = {"um", "min", 50, 4000};
  CHECK_OK(sp_output_units_write("test_units_out", 2, &both));
  const char *text = read_all("test_units_out/units.csv");
  CHECK(text && !strcmp(text, want_2d), "2D units.csv:\n%s", text ? text : "(none)");

  const sp_output_units length = {"um", "", 50, 1};
  CHECK_OK(sp_output_units_write("test_units_out", 3, &length));
  text = read_all("test_units_out/units.csv");
  CHECK(text && !strcmp(text, want_3d), "3D units.csv:\n%s", text ? text : "(none)");

  CHECK(system("rm -f test_units_out/units.csv") == 0, "cannot remove");
  const sp_output_units none = {"", "", 1, 1};
  CHECK_OK(sp_output_units_write("test_units_out", 2, &none));
  CHECK(!read_all("test_units_out/units.csv"), "units.csv written without units");
  TEST_DONE();
}
