/* bad_blob.c -- a blob with a wrong magic, for the error path of the image
 * (test_baremetal.sh: validation fails, FAIL line, exit status 1). */
const unsigned char sinew_bad_blob[1024] = { 'S', 'N', 'W', 'X' };
const unsigned long sinew_bad_blob_size = sizeof sinew_bad_blob;
