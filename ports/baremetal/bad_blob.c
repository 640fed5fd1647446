/* bad_blob.c -- a blob with a wrong magic, for the error path of the image
 * (test_baremetal.sh: validation fails, FAIL line, exit status 1). */
#include <stdint.h>
const unsigned char sinew_bad_blob[64] = { 'S', 'N', 'W', 'X' };
const uint32_t sinew_bad_blob_size = sizeof sinew_bad_blob;
