/* semo_lm3s6965.c: the board file of the `cortex-m` targets for the TI
 * Stellaris LM3S6965 (QEMU's `lm3s6965evb`, the Evalbot's family): the
 * stack, the vector table, and UART0 as the trace's output and a wake-up
 * source (a received byte ends a sleep). The reset code, the clock, the
 * sleep, the exit and the fault handler are the core's (semo_cortex_m.c).
 * Linked with lm3s6965.ld.
 */
#include "semo_internal.h"

/* The main stack, counted in the RAM that arm-none-eabi-size reports (as bss). */
#ifndef SEMO_STACK_BYTES
#define SEMO_STACK_BYTES 2048
#endif

#define REG(addr) (*(volatile uint32_t *)(addr))
#define UART0_DR REG(0x4000C000u)
#define UART0_FR REG(0x4000C018u)
#define UART_FR_TXFF (1u << 5)
#define UART_FR_RXFE (1u << 4)
#define UART0_IM REG(0x4000C038u)
#define UART0_ICR REG(0x4000C044u)
#define UART_IM_RX (1u << 4)
#define UART_IM_RT (1u << 6)
#define NVIC_ISER0 REG(0xE000E100u)
#define UART0_IRQ 5u

/* Its own section (lm3s6965.ld): zeroing .bss must not wipe the stack it runs on. */
__attribute__((section(".stack"))) static uint32_t g_stack[SEMO_STACK_BYTES / 4];
static volatile uint32_t g_uart_input; /* bytes received (and discarded) */

/* ---------------------------------------------------------------- board */

void semo__board_init(void)
{
    semo__systick_start();
    UART0_IM = UART_IM_RX | UART_IM_RT;
    NVIC_ISER0 = 1u << UART0_IRQ;
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

/* A received byte only wakes the loop (nothing reads the UART yet). */
static void uart0(void)
{
    while (!(UART0_FR & UART_FR_RXFE)) {
        (void)UART0_DR;
        g_uart_input++;
    }
    UART0_ICR = UART_IM_RX | UART_IM_RT;
}

typedef union {
    uint32_t *stack_top;
    void (*handler)(void);
} vector;

__attribute__((section(".isr_vector"), used)) static const vector g_vectors[16 + UART0_IRQ + 1] = {
    {.stack_top = &g_stack[SEMO_STACK_BYTES / 4]},
    {.handler = semo__reset},
    {.handler = semo__fault}, /* NMI */
    {.handler = semo__fault}, /* HardFault */
    {.handler = semo__fault}, /* MemManage */
    {.handler = semo__fault}, /* BusFault */
    {.handler = semo__fault}, /* UsageFault */
    {0},
    {0},
    {0},
    {0},
    {.handler = semo__fault}, /* SVCall */
    {.handler = semo__fault}, /* DebugMonitor */
    {0},
    {.handler = semo__fault}, /* PendSV */
    {.handler = semo__systick},
    /* External interrupts 0..4 (GPIO ports A to E) stay disabled. */
    {.handler = semo__fault},
    {.handler = semo__fault},
    {.handler = semo__fault},
    {.handler = semo__fault},
    {.handler = semo__fault},
    {.handler = uart0},
};
