/* Compares a tile set embedded at build time (kdm_bake_tileset's EMBED) with the file it was baked to. */
#include <stdio.h>
#include <string.h>

#include KDM_EMBED_HEADER

int main(void) {
  static unsigned char file_bytes[1 << 20];
  size_t n = 0;
  FILE* file = fopen(KDM_EMBED_FILE, "rb");
  if (file == NULL) return 1;
  n = fread(file_bytes, 1, sizeof file_bytes, file);
  fclose(file);
  if (n != KDM_EMBED_SIZE || memcmp(file_bytes, KDM_EMBED_BYTES, n) != 0) {
    printf("%s: the embedded bytes are not the file's\n", KDM_EMBED_FILE);
    return 1;
  }
  printf("embedded %lu bytes, the file's\n", (unsigned long)n);
  return 0;
}
