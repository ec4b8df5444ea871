/* semo_lm3s6965.c: the board file of the `cortex-m` targets for the TI
 * Stellaris LM3S6965 (QEMU's `lm3s6965evb`, the Evalbot's family): the
 * vector table and reset code, and UART0 as the trace's output and a
 * wake-up source (a received byte ends a sleep). The clock, the sleep and
 * the exit are the core's (semo_systick.c). Linked with lm3s6965.ld; no C
 * library start-up files (-nostartfiles).
 */
#include "semo_internal.h"

#include <string.h>

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

/* A received byte only wakes the loop (nothing reads the UART yet). */
static void uart0(void)
{
    while (!(UART0_FR & UART_FR_RXFE)) {
        (void)UART0_DR;
        g_uart_input++;
    }
    UART0_ICR = UART_IM_RX | UART_IM_RT;
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

__attribute__((section(".isr_vector"), used)) static const vector g_vectors[16 + UART0_IRQ + 1] = {
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
    {.handler = semo__systick},
    /* External interrupts 0..4 (GPIO ports A to E) stay disabled. */
    {.handler = fault},
    {.handler = fault},
    {.handler = fault},
    {.handler = fault},
    {.handler = fault},
    {.handler = uart0},
};
