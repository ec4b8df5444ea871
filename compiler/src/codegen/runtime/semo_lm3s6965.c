/* semo_lm3s6965.c: the board file of the `cortex-m` targets for the TI
 * Stellaris LM3S6965 (QEMU's `lm3s6965evb`, the Evalbot's family): the
 * stack, the vector table, and UART0 as the trace's output and a wake-up
 * source (a received byte ends a sleep). With -DSEMO_LINK (a robot that
 * messages other robots) UART1 (U1Rx on PD2, U1Tx on PD3; QEMU's second
 * `-serial`) is the link to `semo gateway` (semo_static_link.c): written
 * polled, read by its interrupt into the core's receive ring.
 * The reset code, the clock, the sleep, the exit and the fault handler are
 * the core's (semo_cortex_m.c). Linked with lm3s6965.ld.
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
#ifdef SEMO_LINK
#include "semo_link.h"
#define UART1_DR REG(0x4000D000u)
#define UART1_FR REG(0x4000D018u)
#define UART1_IBRD REG(0x4000D024u)
#define UART1_FBRD REG(0x4000D028u)
#define UART1_LCRH REG(0x4000D02Cu)
#define UART1_CTL REG(0x4000D030u)
#define UART1_IM REG(0x4000D038u)
#define UART1_ICR REG(0x4000D044u)
#define UART_LCRH_8N1_FIFO 0x70u /* 8 data bits, no parity, 1 stop bit, FIFOs on */
#define UART_CTL_ON 0x301u       /* UARTEN, TXE, RXE */
#define UART1_IRQ 6u
#define SYSCTL_RCGC1 REG(0x400FE104u) /* bit 1: UART1 */
#define SYSCTL_RCGC2 REG(0x400FE108u) /* bit 3: GPIO port D */
#define GPIOD_AFSEL REG(0x40007420u)
#define GPIOD_DEN REG(0x4000751Cu)
#define PD2_PD3 0x0Cu
/* The link's rate: 115200 baud unless the Makefile says otherwise. */
#ifndef SEMO_LINK_BAUD
#define SEMO_LINK_BAUD 115200u
#endif
#define LAST_IRQ UART1_IRQ
#else
#define LAST_IRQ UART0_IRQ
#endif

/* Its own section (lm3s6965.ld): zeroing .bss must not wipe the stack it runs on. */
__attribute__((section(".stack"))) static uint32_t g_stack[SEMO_STACK_BYTES / 4];
static volatile uint32_t g_uart_input; /* bytes received (and discarded) */

/* ---------------------------------------------------------------- board */

#ifdef SEMO_LINK
static void link_init(void)
{
    SYSCTL_RCGC1 |= 1u << 1;
    SYSCTL_RCGC2 |= 1u << 3;
    GPIOD_AFSEL |= PD2_PD3;
    GPIOD_DEN |= PD2_PD3;
    UART1_CTL = 0;
    /* The divisor in 64ths: SEMO_CPU_HZ / (16 * baud), rounded. */
    uint32_t divisor = (SEMO_CPU_HZ * 4u + SEMO_LINK_BAUD / 2u) / SEMO_LINK_BAUD;
    UART1_IBRD = divisor >> 6;
    UART1_FBRD = divisor & 63u;
    UART1_LCRH = UART_LCRH_8N1_FIFO;
    UART1_IM = UART_IM_RX | UART_IM_RT;
    UART1_CTL = UART_CTL_ON;
}

void semo__board_link_put(const unsigned char *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        while (UART1_FR & UART_FR_TXFF)
            ;
        UART1_DR = bytes[i];
    }
}

/* Every byte the FIFO holds goes to the core's receive ring. */
static void uart1(void)
{
    while (!(UART1_FR & UART_FR_RXFE))
        semo__board_link_received((unsigned char)UART1_DR);
    UART1_ICR = UART_IM_RX | UART_IM_RT;
}
#endif

void semo__board_init(void)
{
    semo__systick_start();
    UART0_IM = UART_IM_RX | UART_IM_RT;
#ifdef SEMO_LINK
    link_init();
    NVIC_ISER0 = 1u << UART0_IRQ | 1u << UART1_IRQ;
#else
    NVIC_ISER0 = 1u << UART0_IRQ;
#endif
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

__attribute__((section(".isr_vector"), used)) static const vector g_vectors[16 + LAST_IRQ + 1] = {
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
#ifdef SEMO_LINK
    {.handler = uart1},
#endif
};
