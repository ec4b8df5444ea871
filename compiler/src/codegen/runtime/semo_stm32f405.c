/* semo_stm32f405.c: the board file of the `stm32f4` targets for the ST
 * STM32F405 (a Cortex-M4; QEMU's `netduinoplus2`, the family of the
 * OpenCR's STM32F7): the stack, the vector table, and USART1 as the
 * trace's output and a wake-up source (a received byte ends a sleep). The
 * reset code, the clock, the sleep, the exit and the fault handler are the
 * core's (semo_cortex_m.c). Linked with stm32f405.ld (flash at 0x08000000,
 * which the chip also shows at 0, where the core reads its vector table at
 * reset). The floating-point unit stays off: the Makefile compiles for the
 * soft-float ABI, as on the Cortex-M3.
 *
 * The clock tree is left as it is: SEMO_CPU_HZ (168 MHz) is the core clock
 * QEMU's netduinoplus2 runs, whatever RCC says. A real STM32F405 starts on
 * its 16 MHz internal oscillator: there, build with `make
 * SEMO_CPU_HZ=16000000`, or set the PLL to 168 MHz before
 * semo__systick_start.
 */
#include "semo_internal.h"

/* The main stack, counted in the RAM that arm-none-eabi-size reports (as bss). */
#ifndef SEMO_STACK_BYTES
#define SEMO_STACK_BYTES 2048
#endif

#define REG(addr) (*(volatile uint32_t *)(addr))
/* USART1 (APB2): status, data and control register 1. */
#define USART1_SR REG(0x40011000u)
#define USART1_DR REG(0x40011004u)
#define USART1_CR1 REG(0x4001100Cu)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TXE (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_UE (1u << 13)
/* RCC: the clock of USART1 (APB2ENR bit 4). */
#define RCC_APB2ENR REG(0x40023844u)
#define RCC_APB2ENR_USART1EN (1u << 4)
#define NVIC_ISER(n) REG(0xE000E100u + 4u * (n))
#define USART1_IRQ 37u

/* Its own section (stm32f405.ld): zeroing .bss must not wipe the stack it runs on. */
__attribute__((section(".stack"))) static uint32_t g_stack[SEMO_STACK_BYTES / 4];
static volatile uint32_t g_uart_input; /* bytes received (and discarded) */

/* ---------------------------------------------------------------- board */

void semo__board_init(void)
{
    semo__systick_start();
    RCC_APB2ENR |= RCC_APB2ENR_USART1EN;
    /* The reset's baud rate stands: the port is the board's console. */
    USART1_CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
    NVIC_ISER(USART1_IRQ / 32u) = 1u << (USART1_IRQ % 32u);
}

void semo__board_put(void *ctx, const char *bytes, size_t n)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        while (!(USART1_SR & USART_SR_TXE))
            ;
        USART1_DR = (uint32_t)(unsigned char)bytes[i];
    }
}

/* A received byte only wakes the loop (nothing reads the port yet):
 * reading the data register clears the interrupt. */
static void usart1(void)
{
    while (USART1_SR & USART_SR_RXNE) {
        (void)USART1_DR;
        g_uart_input++;
    }
}

typedef union {
    uint32_t *stack_top;
    void (*handler)(void);
} vector;

/* The core's 16 vectors, then the chip's interrupts up to USART1's (37):
 * the others stay disabled, and one taken anyway is a fault. */
#define FAULT {.handler = semo__fault}
#define FAULT4 FAULT, FAULT, FAULT, FAULT
__attribute__((section(".isr_vector"), used)) static const vector g_vectors[16 + USART1_IRQ + 1] = {
    {.stack_top = &g_stack[SEMO_STACK_BYTES / 4]},
    {.handler = semo__reset},
    FAULT, /* NMI */
    FAULT, /* HardFault */
    FAULT, /* MemManage */
    FAULT, /* BusFault */
    FAULT, /* UsageFault */
    {0},
    {0},
    {0},
    {0},
    FAULT, /* SVCall */
    FAULT, /* DebugMonitor */
    {0},
    FAULT, /* PendSV */
    {.handler = semo__systick},
    /* Interrupts 0..36 (watchdog, timers, DMA, I2C, SPI, ...). */
    FAULT4, FAULT4, FAULT4, FAULT4, FAULT4, FAULT4, FAULT4, FAULT4, FAULT4,
    FAULT,
    {.handler = usart1}, /* 37 */
};
