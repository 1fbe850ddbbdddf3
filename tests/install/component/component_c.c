/* The installed C API from C, included as <ldc.h>. */
#include <ldc.h>
#include <stdio.h>
#include <string.h>

int main(void) {
  if (strcmp(ldc_version_string(), LDC_VERSION_STRING) != 0) {
    printf("component c: header %s, library %s\n", LDC_VERSION_STRING, ldc_version_string());
    return 1;
  }
  ldc_terrain_config t;
  ldc_terrain_config_default(&t);
  t.size_x = t.size_y = 10.0;
  t.cell_size = 0.4;
  ldc_world* w = NULL;
  if (ldc_world_create_terrain(&t, &w) != LDC_OK) {
    printf("component c: %s\n", ldc_last_error());
    return 1;
  }
  ldc_world_info info;
  ldc_world_get_info(w, &info);
  printf("component c: ok: ldc %s, %llu points\n", ldc_version_string(), (unsigned long long)info.points);
  ldc_world_destroy(w);
  return 0;
}
