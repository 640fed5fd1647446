/* startup.c -- minimal Cortex-M4 start: vector table, reset handler that
 * copies .data, zeroes .bss, paints the stack (to measure its peak use) and
 * calls main; faults report through semihosting and exit non-zero. */
#include <stdint.h>
#include <string.h>
#include "semihost.h"

extern uint32_t __data_load[], __data_start[], __data_end[], __bss_start[], __bss_end[];
extern uint32_t __stack_limit[], __stack_top[];
int main(void);
void sn_bm_reset(void);

#define SN_BM_PAINT 0xA5A5A5A5u

static void fault(void) {
    sn_bm_puts("FAIL: hard fault\n");
    sn_bm_exit(3);
}

typedef union { void (*fn)(void); uint32_t *sp; } vector;

/* SP, reset, NMI, HardFault, MemManage, BusFault, UsageFault: enough for a
 * program that enables no interrupts. */
__attribute__((section(".vectors"), used))
static const vector vectors[16] = {
    { .sp = __stack_top }, { .fn = sn_bm_reset }, { .fn = fault }, { .fn = fault },
    { .fn = fault }, { .fn = fault }, { .fn = fault }, { .fn = 0 },
    { .fn = 0 }, { .fn = 0 }, { .fn = 0 }, { .fn = fault },
    { .fn = fault }, { .fn = 0 }, { .fn = fault }, { .fn = fault },
};

/* Peak stack use in bytes: the lowest painted word that was overwritten. */
uint32_t sn_bm_stack_used(void) {
    const uint32_t *p = __stack_limit;
    while (p < __stack_top && *p == SN_BM_PAINT) p++;
    return (uint32_t)((uintptr_t)__stack_top - (uintptr_t)p);
}

void sn_bm_reset(void) {
    uint32_t *p;
    memcpy(__data_start, __data_load, (size_t)((uintptr_t)__data_end - (uintptr_t)__data_start));
    memset(__bss_start, 0, (size_t)((uintptr_t)__bss_end - (uintptr_t)__bss_start));
    /* paint up to a margin below our own frame */
    for (p = __stack_limit; (uintptr_t)p < (uintptr_t)__builtin_frame_address(0) - 256u; p++)
        *p = SN_BM_PAINT;
    sn_bm_exit((uint32_t)main());
}
