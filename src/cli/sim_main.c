/* hearth-sim: the simulation commands (`hearth sim ...`) in their own
 * executable, so that MuJoCo, Mesa and HDF5 (about 50 shared libraries)
 * are loaded only by the commands that use them; `hearth sim` runs this
 * program with the same arguments. */
#include "cli/cli.h"

extern int hearth_cmd_sim(int argc, char **argv);

int main(int argc, char **argv) { return hearth_cmd_sim(argc, argv); }
