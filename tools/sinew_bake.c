/* sinew_bake.c -- command line of the host tool. */
#include "sb.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sinew-bake DESCRIPTION -o OUT.blob [--c-array OUT.c [--name SYMBOL]]\n"
            "                  [--flavour fixed|float|double] [--quiet]\n"
            "       (-o may be left out when --c-array is given)\n"
            "Bakes a character (OBJ mesh + text description, see tools/DESCRIPTION.md) into a\n"
            "Sinew blob (runtime/BLOB.md).\n"
            "  -o OUT.blob       binary blob (written to OUT.blob.tmp, then renamed)\n"
            "  --c-array OUT.c   also write the blob as an 8-aligned C99 array\n"
            "  --name SYMBOL     C symbol of the array (default sinew_blob); SYMBOL_size holds the size\n"
            "  --flavour F       fixed (default, int32 Q formats), float (float32), double (float64, host/tests)\n"
            "  --quiet           no summary or progress\n"
            "  --help            this text\n");
}

int main(int argc, char **argv)
{
    const char *desc = NULL, *out = NULL, *carray = NULL, *name = "sinew_blob";
    int flavour = SB_FIXED, quiet = 0, i;
    sb_model o;
    sb_blob b;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) quiet = 1;
        else if (!strcmp(a, "-o") || !strcmp(a, "--c-array") || !strcmp(a, "--name") || !strcmp(a, "--flavour")) {
            if (i + 1 >= argc) { fprintf(stderr, "sinew-bake: %s needs a value\n", a); return 2; }
            if (!strcmp(a, "-o")) out = argv[++i];
            else if (!strcmp(a, "--c-array")) carray = argv[++i];
            else if (!strcmp(a, "--name")) name = argv[++i];
            else {
                const char *f = argv[++i];
                if (!strcmp(f, "fixed")) flavour = SB_FIXED;
                else if (!strcmp(f, "float")) flavour = SB_FLOAT;
                else if (!strcmp(f, "double")) flavour = SB_DOUBLE;
                else { fprintf(stderr, "sinew-bake: unknown flavour '%s' (fixed, float or double)\n", f); return 2; }
            }
        } else if (a[0] == '-' && a[1]) { fprintf(stderr, "sinew-bake: unknown option '%s' (try --help)\n", a); return 2; }
        else if (!desc) desc = a;
        else { fprintf(stderr, "sinew-bake: more than one description given ('%s')\n", a); return 2; }
    }
    if (!desc || (!out && !carray)) { usage(stderr); return 2; }
    if (carray) {   /* check the symbol before any work or output */
        const char *c;
        for (c = name; *c; c++)
            if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || *c == '_' || (c != name && *c >= '0' && *c <= '9'))) break;
        if (*c || !*name) { fprintf(stderr, "sinew-bake: --name '%s' is not a C identifier\n", name); return 2; }
    }
    if (sb_bake_file(desc, flavour, quiet, &o, &b)) { fprintf(stderr, "sinew-bake: error: %s\n", sb_error()); return 1; }
    if ((out && sb_write_file(out, b.bytes, b.size)) || (carray && sb_write_c_array(carray, name, b.bytes, b.size))) {
        fprintf(stderr, "sinew-bake: error: %s\n", sb_error());
        if (out) remove(out);   /* all or nothing */
        sb_blob_free(&b); sb_model_free(&o);
        return 1;
    }
    sb_blob_free(&b);
    sb_model_free(&o);
    return 0;
}
