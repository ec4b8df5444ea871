/* semo_lm3s6965.c: the board file of the `cortex-m` targets for the TI
 * Stellaris LM3S6965 (QEMU's `lm3s6965evb`, the Evalbot's family): the
 * vector table and reset code, SysTick as the millisecond clock, UART0 as
 * the trace's output, and the exit (through semihosting when built with
 * -DSEMO_SEMIHOSTING, so that a QEMU run ends; on a board the robot halts).
 * Linked with lm3s6965.ld; no C library start-up files (-nostartfiles).
 */
#include "semo_internal.h"

#include <string.h>

/* The main stack, counted in the RAM that arm-none-eabi-size reports (as bss). */
#ifndef SEMO_STACK_BYTES
#define SEMO_STACK_BYTES 2048
#endif
/* The core clock SysTick counts (QEMU's lm3s6965evb runs at 12 MHz). */
#ifndef SEMO_CPU_HZ
#define SEMO_CPU_HZ 12000000u
#endif

#define REG(addr) (*(volatile uint32_t *)(addr))
#define UART0_DR REG(0x4000C000u)
#define UART0_FR REG(0x4000C018u)
#define UART_FR_TXFF (1u << 5)
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)

/* Its own section (lm3s6965.ld): zeroing .bss must not wipe the stack it runs on. */
__attribute__((section(".stack"))) static uint32_t g_stack[SEMO_STACK_BYTES / 4];
static volatile uint32_t g_ticks; /* ms since semo__board_init */

/* ---------------------------------------------------------------- board */

void semo__board_init(void)
{
    SYST_RVR = SEMO_CPU_HZ / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = 7u; /* processor clock, interrupt, enabled */
}

int64_t semo__board_now_ms(void)
{
    return (int64_t)g_ticks;
}

void semo__board_put(void *ctx, const char *bytes, size_t n)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        while (UART0_FR & UART_FR_TXFF)
            ;
        UART0_DR = (uint32_t)(unsigned char)bytes[i];
    }
}

/* Sleeps until the next interrupt (the next tick at the latest). */
void semo__board_idle(void)
{
    __asm__ volatile("wfi");
}

void semo__board_exit(int status)
{
#ifdef SEMO_SEMIHOSTING
    /* SYS_EXIT with ADP_Stopped_ApplicationExit (QEMU exits 0) or
     * ADP_Stopped_RunTimeErrorUnknown (QEMU exits 1). */
    register uint32_t op __asm__("r0") = 0x18u;
    register uint32_t reason __asm__("r1") = status == 0 ? 0x20026u : 0x20023u;
    __asm__ volatile("bkpt 0xab" : : "r"(op), "r"(reason) : "memory");
#else
    (void)status;
#endif
    SYST_CSR = 0;
    for (;;)
        __asm__ volatile("wfi");
}

/* ------------------------------------------------------------- start-up */

int main(int argc, char **argv);

extern uint32_t _sidata[], _sdata[], _edata[], _sbss[], _ebss[];

void semo__reset(void);
void semo__reset(void)
{
    memcpy(_sdata, _sidata, (size_t)((char *)_edata - (char *)_sdata));
    memset(_sbss, 0, (size_t)((char *)_ebss - (char *)_sbss));
    semo__board_exit(main(0, NULL));
}

static void systick(void)
{
    g_ticks++;
}

/* A fault or an unexpected interrupt: the program cannot go on. */
static void fault(void)
{
    static const char message[] = "semo runtime: fault\n";
    semo__board_put(NULL, message, sizeof message - 1);
    semo__board_exit(1);
}

typedef union {
    uint32_t *stack_top;
    void (*handler)(void);
} vector;

__attribute__((section(".isr_vector"), used)) static const vector g_vectors[16] = {
    {.stack_top = &g_stack[SEMO_STACK_BYTES / 4]},
    {.handler = semo__reset},
    {.handler = fault}, /* NMI */
    {.handler = fault}, /* HardFault */
    {.handler = fault}, /* MemManage */
    {.handler = fault}, /* BusFault */
    {.handler = fault}, /* UsageFault */
    {0},
    {0},
    {0},
    {0},
    {.handler = fault}, /* SVCall */
    {.handler = fault}, /* DebugMonitor */
    {0},
    {.handler = fault}, /* PendSV */
    {.handler = systick},
};
