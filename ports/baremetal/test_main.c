/* test_main.c -- main of a host test program built for the Cortex-M4 image
 * (the test's own main renamed sn_test_main): newlib's semihosting
 * (librdimon) carries its printf to QEMU's stdout; startup.c's reset handler
 * passes the return value to SYS_EXIT_EXTENDED. */
extern void initialise_monitor_handles(void);
int sn_test_main(void);
int main(void) {
    initialise_monitor_handles();
    return sn_test_main();
}
