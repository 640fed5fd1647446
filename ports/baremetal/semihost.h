/* semihost.h -- ARM semihosting (bkpt 0xab on M-profile) and the few CMSDK
 * registers the port uses; no CMSIS, the defs are small enough to own. */
#ifndef SN_BM_SEMIHOST_H
#define SN_BM_SEMIHOST_H

#include <stdint.h>

#define SN_SYS_WRITE0 0x04u
#define SN_SYS_EXIT_EXTENDED 0x20u
#define SN_ADP_STOPPED_APPLICATION_EXIT 0x20026u

static inline uint32_t sn_semihost(uint32_t op, const void *arg) {
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static inline void sn_bm_puts(const char *s) { (void)sn_semihost(SN_SYS_WRITE0, s); }

/* SYS_EXIT_EXTENDED: plain SYS_EXIT on A32/T32 cannot carry a status. */
static inline void sn_bm_exit(uint32_t code) {
    uint32_t block[2];
    block[0] = SN_ADP_STOPPED_APPLICATION_EXIT;
    block[1] = code;
    for (;;) (void)sn_semihost(SN_SYS_EXIT_EXTENDED, block);
}

/* CMSDK APB timer 0 (down-counter clocked by the 25 MHz system clock). */
#define SN_CMSDK_TIMER0 ((volatile uint32_t *)0x40000000u)
#define SN_TIMER_CTRL 0
#define SN_TIMER_VALUE 1
#define SN_TIMER_RELOAD 2

/* decimal output of an unsigned value, and "key<value>\n" lines */
static inline void sn_bm_put_u64(uint64_t v) {
    char d[21];
    int n = 20;
    d[n] = 0;
    do { d[--n] = (char)('0' + (int)(v % 10u)); v /= 10u; } while (v);
    sn_bm_puts(&d[n]);
}
static inline void sn_bm_put_kv(const char *k, uint64_t v) {
    sn_bm_puts(k); sn_bm_put_u64(v); sn_bm_puts("\n");
}

static inline uint32_t sn_bm_timer_now(void) { return SN_CMSDK_TIMER0[SN_TIMER_VALUE]; }

/* Ticks of a loop of exactly 2*n instructions (subs + bne), so that ticks
 * convert to instructions without trusting the clock rate. */
static inline uint32_t sn_bm_calibrate(uint32_t n) {
    uint32_t t0, t1, r = n;
    t0 = sn_bm_timer_now();
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(r) : : "cc");
    t1 = sn_bm_timer_now();
    return t0 - t1;
}

#endif /* SN_BM_SEMIHOST_H */
