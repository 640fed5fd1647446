/* sinew_retarget.c -- main of sinew-retarget (tools/sb_retarget_cli.c); the
 * same command is meant to become 'sinew-rig retarget' once the rig tool exists. */
int sb_retarget_cli(int argc, char **argv, const char *prog);
int main(int argc, char **argv) { return sb_retarget_cli(argc, argv, "sinew-retarget"); }
