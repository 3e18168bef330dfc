/* Hostile releases against the built `hearth`: files that are not regular
 * files (FIFO, directory, device, socket), manifests naming one file twice,
 * documents that contradict each other, killed writers' temporaries, images
 * declaring a huge size, write errors. Every case must fail at once with a
 * message naming the file (or, for a clean-up, succeed), leave no output or
 * temporary behind and stay under 300 MB.
 *
 * One small release (one cup, two states of two views, calibration
 * captures) is made and built once; each case copies it (cp -a keeps the
 * build's stamps fresh) and spoils the copy. */
#include <sys/stat.h>
#include <zlib.h>
#include "faults.h"
#include "hearth/image.h"

/* the spoiled copy: R; its instance: I */
#define COPY "cp -a \"$SHARED/rel\" R && I=R/instances/cup_01 && "
/* a process id that is no longer running */
#define DEAD "dead=$(sh -c 'echo $$') && "
#define TEMPS "R/instances/cup_01/derived/*.tmp-*"
#define STAMP_TEMPS "R/instances/cup_01/derived/.stamps/*.tmp-*"

static const fault_case k_cases[] = {
    /* ---- 1. not regular files: refused at once, named, never waited on -- */
    {"fifo_thermal_map",
     COPY "rm $I/raw/hot/thermal/v00.csv && mkfifo $I/raw/hot/thermal/v00.csv",
     "$HEARTH map R --state hot --resolution 32 --threads 2",
     {"raw/hot/thermal/v00.csv: not a regular file (a FIFO)"},
     {TEMPS},
     20},
    {"fifo_thermal_build",
     COPY "rm $I/raw/hot/thermal/v00.csv && mkfifo $I/raw/hot/thermal/v00.csv",
     "$HEARTH build R --resolution 32 --threads 2",
     {"raw/hot/thermal/v00.csv: not a regular file (a FIFO)", "FAILED"},
     {TEMPS, STAMP_TEMPS},
     20},
    {"fifo_manifest_inspect",
     COPY "rm $I/raw/hot/manifest.json && mkfifo $I/raw/hot/manifest.json",
     "$HEARTH inspect R/instances/cup_01/raw/hot/manifest.json",
     {"raw/hot/manifest.json: not a regular file (a FIFO)"},
     {NULL},
     10},
    /* validate says what the file is, not that it is missing */
    {"fifo_thermal_validate",
     COPY "rm $I/raw/hot/thermal/v00.csv && mkfifo $I/raw/hot/thermal/v00.csv",
     "$HEARTH validate R > out.txt 2>&1; rc=$?; cat out.txt; "
     "if grep -q 'v00.csv: missing' out.txt; then exit 0; fi; exit $rc",
     {"raw/hot/thermal/v00.csv: not a regular file (a FIFO)"},
     {NULL},
     20},
    {"fifo_instance_build",
     COPY "rm $I/instance.json && mkfifo $I/instance.json",
     "$HEARTH build R --resolution 32 --threads 2",
     {"cup_01/instance.json: not a regular file (a FIFO)"},
     {TEMPS},
     20},
    {"dir_as_rgb_map",
     COPY "rm $I/raw/neutral/rgb/v00.jpg && mkdir $I/raw/neutral/rgb/v00.jpg",
     "$HEARTH map R --rgb --state hot --resolution 32 --threads 2",
     {"raw/neutral/rgb/v00.jpg: not a regular file (a directory)"},
     {TEMPS},
     20},
    {"device_as_depth_build",
     COPY "rm $I/raw/hot/depth/v00.png && ln -s /dev/zero $I/raw/hot/depth/v00.png",
     "$HEARTH build R --resolution 32 --threads 2",
     {"raw/hot/depth/v00.png: not a regular file (a character device)"},
     {TEMPS, STAMP_TEMPS},
     20},
    {"socket_as_depth_build",
     COPY "rm $I/raw/hot/depth/v00.png && python3 -c 'import socket, sys; "
          "socket.socket(socket.AF_UNIX).bind(sys.argv[1])' $I/raw/hot/depth/v00.png",
     "$HEARTH build R --resolution 32 --threads 2",
     {"raw/hot/depth/v00.png: not a regular file (a socket)"},
     {TEMPS, STAMP_TEMPS},
     20},

    /* ---- 2. inputs that contradict each other: refused by name ----------- */
    {"dup_thermal_map",
     COPY "sed -i 's|\"thermal/v15.csv\"|\"thermal/v00.csv\"|' $I/raw/hot/manifest.json",
     "$HEARTH map R --state hot --resolution 32 --threads 2",
     {"raw/hot/manifest.json: views[1].thermal:",
      "view \"v15\" names \"thermal/v00.csv\", the file of view \"v00\""},
     {TEMPS},
     20},
    {"dup_rgb_validate",
     COPY "sed -i 's|\"rgb/v15.jpg\"|\"rgb/v00.jpg\"|' $I/raw/neutral/manifest.json",
     "$HEARTH validate R",
     {"raw/neutral/manifest.json: views[1].rgb:", "the file of view \"v00\" (views[0].rgb)"},
     {NULL},
     20},
    /* another spelling of the same file */
    {"dup_depth_build",
     COPY "sed -i 's|\"depth/v15.png\"|\"./depth/v00.png\"|' $I/raw/hot/manifest.json",
     "$HEARTH build R --resolution 32 --threads 2",
     {"raw/hot/manifest.json: views[1].depth:",
      "names \"./depth/v00.png\", the file of view \"v00\""},
     {TEMPS, STAMP_TEMPS},
     20},
    {"factory_size_calibrate",
     COPY
     "sed -i '0,/\"width\": 1920/s//\"width\": 1280/' R/calibration/factory.json && "
     "rm R/calibration/rig.json R/calibration/rig_opencv.yaml R/calibration/calibration_report.json",
     "$HEARTH calibrate R",
     {"calibration/factory.json: the colour camera is 1280x1080, but capture",
      "captures/stereo/p000_rgb.jpg is 1920x1080"},
     {"R/calibration/rig.json", "R/calibration/rig_opencv.yaml",
      "R/calibration/calibration_report.json", "R/calibration/*.tmp-*"},
     20},
    {"instance_id_map",
     COPY "sed -i 's/\"id\": \"cup_01\"/\"id\": \"cup_02\"/' $I/instance.json",
     "$HEARTH map R --state hot --resolution 32 --threads 2",
     {"cup_01/instance.json: id: \"cup_02\", but the directory is instances/cup_01"},
     {TEMPS},
     20},
    {"instance_id_build",
     COPY "sed -i 's/\"id\": \"cup_01\"/\"id\": \"cup_02\"/' $I/instance.json",
     "$HEARTH build R --resolution 32 --threads 2",
     {"cup_01/instance.json: id: \"cup_02\", but the directory is instances/cup_01", "FAILED"},
     {TEMPS, STAMP_TEMPS},
     20},
    /* the rig is what disagrees with every CSV: blamed, not the CSV */
    {"rig_thermal_width_map",
     COPY
     "sed -i '/\"thermal\"/,/\"width\"/s/\"width\": 256/\"width\": 320/' R/calibration/rig.json",
     "$HEARTH map R --state hot --resolution 32 --threads 2",
     {"calibration/rig.json: the thermal camera is 320x192, but",
      "thermal/v00.csv is a 256x192 matrix"},
     {TEMPS},
     20},

    /* ---- 3. map --rgb: the bake and the maps succeed or fail together ---- */
    /* the bake reads the first state's colour views: a broken one must not
       leave hot re-mapped */
    {"map_rgb_bad_bake",
     COPY
     "head -c 2000 $I/raw/neutral/rgb/v15.jpg > x.jpg && mv x.jpg $I/raw/neutral/rgb/v15.jpg && "
     "ls -i $I/derived/hot/* $I/derived/rgb_texture.png $I/derived/mesh.glb > before",
     "$HEARTH map R --rgb --state hot --resolution 32 --threads 2; rc=$?; "
     "ls -i R/instances/cup_01/derived/hot/* R/instances/cup_01/derived/rgb_texture.png "
     "R/instances/cup_01/derived/mesh.glb > after; "
     "cmp -s before after || { echo 'outputs were rewritten'; exit 0; }; exit $rc",
     {"raw/neutral/rgb/v15.jpg"},
     {TEMPS},
     30},
    /* a map that fails after a good bake must not leave the texture re-baked */
    {"map_rgb_bad_map",
     COPY
     "head -c 300 $I/raw/hot/thermal/v15.csv > x.csv && mv x.csv $I/raw/hot/thermal/v15.csv && "
     "ls -i $I/derived/hot/* $I/derived/rgb_texture.png $I/derived/mesh.glb > before",
     "$HEARTH map R --rgb --state hot --resolution 32 --threads 2; rc=$?; "
     "ls -i R/instances/cup_01/derived/hot/* R/instances/cup_01/derived/rgb_texture.png "
     "R/instances/cup_01/derived/mesh.glb > after; "
     "cmp -s before after || { echo 'outputs were rewritten'; exit 0; }; exit $rc",
     {"raw/hot/thermal/v15.csv"},
     {TEMPS},
     30},

    /* ---- 4. what killed writers left: removed by the next run ------------ */
    /* an up-to-date build removes dead writers' temporaries anywhere in its
       instances and calibration/, and keeps a running writer's */
    {"leftover_build_uptodate",
     COPY DEAD
     "D=$I/derived && mkdir $D/hot.tmp-$dead-Qw3Er5 && touch $D/hot.tmp-$dead-Qw3Er5/mask.npy "
     "$D/rgb_texture.png.tmp-$dead-Ab12Cd $D/.stamps/map-hot.json.tmp-$dead-q9Z0xY "
     "$D/overlay/hot/contact_sheet.png.tmp-$dead-Zz9y8X R/calibration/rig.json.tmp-$dead-Zz9y8X",
     "D=R/instances/cup_01/derived && mkdir $D/neutral.tmp-$$-AbCdEf && "
     "$HEARTH build R --resolution 32 --threads 2 && test -d $D/neutral.tmp-$$-AbCdEf && "
     "rmdir $D/neutral.tmp-$$-AbCdEf",
     {" 0 stage(s) run", "removed 5 temporary file(s)/folder(s)"},
     {TEMPS, STAMP_TEMPS, "R/instances/cup_01/derived/overlay/hot/*.tmp-*",
      "R/calibration/*.tmp-*"},
     30,
     0,
     1},
    {"leftover_validate",
     COPY DEAD "mkdir $I/derived/hot.tmp-$dead-Qw3Er5",
     "$HEARTH validate R",
     {"derived/hot.tmp-", "left by an interrupted write"},
     {NULL},
     20},
    {"leftover_map_rerun",
     COPY DEAD "mkdir $I/derived/hot.tmp-$dead-Qw3Er5 $I/derived/hot.tmp-$dead-Old000 && "
               "touch $I/derived/hot.tmp-$dead-Qw3Er5/mask.npy",
     "$HEARTH map R --state hot --resolution 32 --threads 2",
     {"map cup_01/hot:"},
     {TEMPS},
     20,
     0,
     1},
    /* a synth killed for real, then run again */
    {"synth_killed_rerun",
     "($HEARTH synth --out S --draft-rgb --categories cup --views 2 --triangles 600 --texture 64 "
     "--map-res 32 --no-calibration --threads 1 --quiet & pid=$!; "
     "for i in $(seq 1 1000); do ls -d S.tmp-* >/dev/null 2>&1 && break; sleep 0.01; done; "
     "sleep 0.2; kill -9 $pid; wait $pid; true) && ls -d S.tmp-* && test ! -e S",
     "$HEARTH synth --out S --draft-rgb --categories cup --views 2 --triangles 600 --texture 64 "
     "--map-res 32 --no-calibration --threads 2 --quiet && test -f S/release.json",
     {NULL},
     {"S.tmp-*"},
     60,
     0,
     1},

    /* ---- 5. a declared size is checked before the pixels are allocated -- */
    {"depth_png_huge_build",
     COPY "cp \"$SHARED/huge.png\" $I/raw/hot/depth/v00.png",
     "$HEARTH build R --resolution 32 --threads 2",
     {"raw/hot/depth/v00.png: image is 16384x16384, expected 640x576"},
     {TEMPS, STAMP_TEMPS},
     20},
    {"cutout_png_huge_validate",
     COPY "cp \"$SHARED/huge.png\" $I/raw/hot/cutout/v00.png",
     "$HEARTH validate R --decode",
     {"raw/hot/cutout/v00.png: image is 16384x16384, expected 1920x1080"},
     {NULL},
     20},

    /* a 3 GB mesh (sparse) is refused on its 12-byte header, not read whole */
    {"glb_huge_bad_magic_scale",
     COPY "rm $I/recon/mesh.glb && truncate -s 3G $I/recon/mesh.glb",
     "$HEARTH scale R --threads 2",
     {"recon/mesh.glb: header: bad magic 0x00000000"},
     {TEMPS},
     20},
    {"glb_huge_bad_length_scale",
     COPY "printf 'glTF\\002\\000\\000\\000\\144\\000\\000\\000' > $I/recon/mesh.glb && "
          "truncate -s 3G $I/recon/mesh.glb",
     "$HEARTH scale R --threads 2",
     {"recon/mesh.glb: header: length field 100 does not match the file size 3221225472"},
     {TEMPS},
     20},

    /* ---- 6. messages that say which file and why ------------------------- */
    {"jpeg_wrong_size_map_rgb",
     COPY "cp \"$SHARED/small.jpg\" $I/raw/neutral/rgb/v00.jpg",
     "$HEARTH map R --rgb --state hot --resolution 32 --threads 2",
     {"raw/neutral/rgb/v00.jpg: image is 64x48, expected 1920x1080 (the colour camera of"},
     {TEMPS},
     20},
    /* a full disk, as a file size limit: the system's reason is kept */
    {"write_error_reason",
     COPY "true",
     "trap '' XFSZ; ulimit -f 40; $HEARTH map R --state hot --resolution 128 --threads 2",
     {"write failed: File too large"},
     {TEMPS, "R/instances/cup_01/derived/hot/*.tmp-*"},
     20},
    {"factory_inspect",
     COPY "true",
     "$HEARTH inspect R/calibration/factory.json",
     {"factory.json: factory calibration", "rgb      1920x1080"},
     {NULL},
     10,
     0,
     1},
};

/* policy servers that misbehave measure nothing: hearth-sim only */
static const fault_case k_sim_cases[] = {
    {"sim_eval_all_errors",
     "$HEARTH synth --out S --draft-rgb --categories "
     "cup,canned_drink,electric_kettle,eraser,orange,smartphone,sponge --states neutral,hot,iced "
     "--views 1 --triangles 600 --texture 64 --map-res 32 --no-calibration --threads 2 --quiet && "
     "cp S/ground_truth/rig.json S/calibration/rig.json && "
     "$HEARTH build S --resolution 32 --no-bake --threads 2 --quiet",
     "$HEARTH sim eval --policy ws://127.0.0.1:1 --episodes 1 --task H1 --timeout 1 --quiet "
     "--release S --size 16 --image-size 8 --out res",
     {"eval: before the first episode: websocket 127.0.0.1:1: cannot connect"},
     {"res"},
     60},
    /* a killed collection's temporary (dead writer) goes with the next run */
    {"collect_leftover_rerun",
     "$HEARTH synth --out S --draft-rgb --categories "
     "cup,canned_drink,electric_kettle,eraser,orange,smartphone,sponge --states neutral,hot,iced "
     "--views 1 --triangles 600 --texture 64 --map-res 32 --no-calibration --threads 2 --quiet && "
     "dead=$(sh -c 'echo $$') && echo x > out.hdf5.tmp-$dead-abc123",
     "$HEARTH sim collect --task H1 --layouts 1 --max-steps 2 --keep-failures --size 16 "
     "--release S --ground-truth --quiet --out out.hdf5 && test -f out.hdf5",
     {NULL},
     {"out.hdf5.tmp-*"},
     120,
     0,
     1},
};

/* A valid 2 MB PNG of 16384 x 16384 RGBA16 zeros (2 GiB of pixels): one
 * band of 64 rows deflated with a full flush (self-contained, byte-aligned)
 * and repeated for all 256 bands, then an empty final block and the
 * Adler-32 of the zeros. A reader that decodes before checking the size
 * needs the 2 GiB and seconds. */
static void put32(uint8_t *p, uint32_t v) {
  for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (24 - 8 * i));
}

static int write_huge_png(const char *path) {
  const size_t side = 16384, row = side * 8 + 1, band_rows = 64, bands = side / band_rows;
  size_t band = row * band_rows;
  uint8_t *zeros = calloc(band, 1), *b = malloc(band / 64 + 4096);
  z_stream z;
  memset(&z, 0, sizeof z);
  if (!zeros || !b || deflateInit2(&z, 9, Z_DEFLATED, -15, 9, Z_RLE) != Z_OK) return 1;
  z.next_in = zeros;
  z.avail_in = (uInt)band;
  z.next_out = b;
  z.avail_out = (uInt)(band / 64 + 4096);
  int zr = deflate(&z, Z_FULL_FLUSH);
  size_t blen = (size_t)(z.next_out - b);
  deflateEnd(&z);
  free(zeros);
  if (zr != Z_OK || z.avail_in) return 1;
  /* the zlib stream: header, the bands, an empty final fixed block, Adler-32
   * of n zero bytes (a = 1, b = n mod 65521) */
  size_t n = 2 + bands * blen + 2 + 4;
  uint8_t *chunk = malloc(8 + n + 4);
  if (!chunk) return 1;
  put32(chunk, (uint32_t)n);
  memcpy(chunk + 4, "IDAT", 4);
  uint8_t *q = chunk + 8;
  *q++ = 0x78, *q++ = 0xda;
  for (size_t k = 0; k < bands; k++, q += blen) memcpy(q, b, blen);
  *q++ = 0x03, *q++ = 0x00;
  uint64_t total = (uint64_t)row * side;
  put32(q, (uint32_t)((total % 65521) << 16 | 1));
  q += 4;
  put32(q, (uint32_t)crc32(0L, chunk + 4, (uInt)(4 + n)));
  free(b);
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  uint8_t ihdr[25] = {0, 0, 0, 13,   'I', 'H', 'D', 'R', 0, 0, 0x40,
                      0, 0, 0, 0x40, 0,   16,  6,   0,   0, 0};
  put32(ihdr + 21, (uint32_t)crc32(0L, ihdr + 4, 17));
  FILE *f = fopen(path, "wb");
  int bad = !f || fwrite(sig, 1, 8, f) != 8 || fwrite(ihdr, 1, 25, f) != 25 ||
            fwrite(chunk, 1, 8 + n + 4, f) != 8 + n + 4 ||
            fwrite("\0\0\0\0IEND\xae\x42\x60\x82", 1, 12, f) != 12;
  free(chunk);
  if (f && fclose(f) != 0) bad = 1;
  return bad;
}

int main(void) {
  char shared[1100], cmd[4096];
  snprintf(shared, sizeof shared, "%s", test_tmpdir("faults_shared"));
  setenv("SHARED", shared, 1);
  const char *exe = getenv("FAULTS_HEARTH");
  if (!exe || !*exe) exe = HEARTH_EXE;
  /* the release every case copies, built (calibration included) */
  snprintf(cmd, sizeof cmd,
           "cd '%s' && '%s' synth --out rel --draft-rgb --seed 3 --categories cup --views 2 "
           "--triangles 600 --texture 64 --map-res 32 --thermal-frames 4 --stereo-pairs 2 "
           "--threads 2 --quiet && '%s' build rel --resolution 32 --threads 2 --quiet",
           shared, exe, exe);
  if (system(cmd) != 0) {
    fprintf(stderr, "faults: cannot make the shared release in %s\n", shared);
    return 1;
  }
  char path[1200];
  snprintf(path, sizeof path, "%s/huge.png", shared);
  CHECK(write_huge_png(path) == 0);
  hearth_image small;
  hearth_err err = {0};
  CHECK_OK(hearth_image_alloc(&small, 64, 48, 3, HEARTH_PIX_U8, &err), &err);
  snprintf(path, sizeof path, "%s/small.jpg", shared);
  CHECK_OK(hearth_jpeg_write(path, &small, 90, &err), &err);
  hearth_image_free(&small);

  faults_run_all("faults", k_cases, sizeof k_cases / sizeof k_cases[0]);
#ifdef HEARTH_FAULTS_SIM
  faults_run_all("faults_sim", k_sim_cases, sizeof k_sim_cases / sizeof k_sim_cases[0]);
#else
  (void)k_sim_cases;
#endif
  TEST_MAIN_END();
}
