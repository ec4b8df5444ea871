/* semo_stm32f405.c: the board file of the `stm32f4` targets for the ST
 * STM32F405 (a Cortex-M4; QEMU's `netduinoplus2`, the family of the
 * OpenCR's STM32F7): the stack, the vector table, and USART1 as the
 * trace's output and a wake-up source (a received byte ends a sleep). With
 * -DSEMO_LINK (a robot that messages other robots) USART2 (TX on PA2, RX on
 * PA3, alternate function 7; QEMU's second `-serial`) is the link to `semo
 * gateway` (semo_static_link.c): written polled, read by its interrupt into
 * the core's receive ring. The reset code, the clock, the sleep, the exit,
 * the fault handler and the link's receive ring are the core's
 * (semo_cortex_m.c). Linked with stm32f405.ld (flash at 0x08000000,
 * which the chip also shows at 0, where the core reads its vector table at
 * reset). The floating-point unit stays off: the Makefile compiles for the
 * soft-float ABI, as on the Cortex-M3.
 *
 * The clock tree is left as it is: SEMO_CPU_HZ (168 MHz) is the core clock
 * QEMU's netduinoplus2 runs, whatever RCC says. A real STM32F405 starts on
 * its 16 MHz internal oscillator: there, build with `make
 * SEMO_CPU_HZ=16000000`, or set the PLL to 168 MHz before
 * semo__systick_start. USART2's rate is set from its bus clock,
 * SEMO_APB1_HZ: a quarter of the core clock at 168 MHz (the PLL's usual
 * set-up: APB1 at its 42 MHz maximum), the core clock itself below 84 MHz
 * (the reset's dividers); `make SEMO_APB1_HZ=...` for another clock tree.
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
#ifdef SEMO_LINK
#include "semo_link.h"
/* USART2 (APB1): the same registers as USART1's, and its baud rate. */
#define USART2_SR REG(0x40004400u)
#define USART2_DR REG(0x40004404u)
#define USART2_BRR REG(0x40004408u)
#define USART2_CR1 REG(0x4000440Cu)
#define USART2_IRQ 38u
#define RCC_AHB1ENR REG(0x40023830u)
#define RCC_AHB1ENR_GPIOAEN (1u << 0)
#define RCC_APB1ENR REG(0x40023840u)
#define RCC_APB1ENR_USART2EN (1u << 17)
#define GPIOA_MODER REG(0x40020000u)
#define GPIOA_AFRL REG(0x40020020u)
/* PA2 and PA3 in alternate-function mode (0b10), function 7 (USART2). */
#define PA2_PA3_MODER_MASK (0xFu << 4)
#define PA2_PA3_MODER_AF (0xAu << 4)
#define PA2_PA3_AFRL_MASK (0xFFu << 8)
#define PA2_PA3_AFRL_USART2 (0x77u << 8)
#ifndef SEMO_LINK_BAUD
#define SEMO_LINK_BAUD 115200u
#endif
#ifndef SEMO_APB1_HZ
#define SEMO_APB1_HZ (SEMO_CPU_HZ >= 84000000u ? SEMO_CPU_HZ / 4u : SEMO_CPU_HZ)
#endif
#define LAST_IRQ USART2_IRQ
#else
#define LAST_IRQ USART1_IRQ
#endif

/* Its own section (stm32f405.ld): zeroing .bss must not wipe the stack it runs on. */
__attribute__((section(".stack"))) static uint32_t g_stack[SEMO_STACK_BYTES / 4];
static volatile uint32_t g_uart_input; /* bytes received (and discarded) */

/* ---------------------------------------------------------------- board */

#ifdef SEMO_LINK
static void link_init(void)
{
    RCC_AHB1ENR |= RCC_AHB1ENR_GPIOAEN;
    RCC_APB1ENR |= RCC_APB1ENR_USART2EN;
    GPIOA_MODER = (GPIOA_MODER & ~PA2_PA3_MODER_MASK) | PA2_PA3_MODER_AF;
    GPIOA_AFRL = (GPIOA_AFRL & ~PA2_PA3_AFRL_MASK) | PA2_PA3_AFRL_USART2;
    /* Oversampling by 16: the divider in 16ths is the bus clock over the
     * rate, rounded. 8 data bits, no parity, 1 stop bit: the reset's. */
    USART2_BRR = (SEMO_APB1_HZ + SEMO_LINK_BAUD / 2u) / SEMO_LINK_BAUD;
    USART2_CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
}

void semo__board_link_put(const unsigned char *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        while (!(USART2_SR & USART_SR_TXE))
            ;
        USART2_DR = bytes[i];
    }
}

/* Reading the data register takes the byte and clears the interrupt. */
static void usart2(void)
{
    while (USART2_SR & USART_SR_RXNE)
        semo__board_link_received((unsigned char)USART2_DR);
}
#endif

void semo__board_init(void)
{
    semo__systick_start();
    RCC_APB2ENR |= RCC_APB2ENR_USART1EN;
    /* The reset's baud rate stands: the port is the board's console. */
    USART1_CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
    NVIC_ISER(USART1_IRQ / 32u) = 1u << (USART1_IRQ % 32u);
#ifdef SEMO_LINK
    link_init();
    NVIC_ISER(USART2_IRQ / 32u) = 1u << (USART2_IRQ % 32u);
#endif
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

/* The core's 16 vectors, then the chip's interrupts up to USART1's (37),
 * or USART2's (38) with the link:
 * the others stay disabled, and one taken anyway is a fault. */
#define FAULT {.handler = semo__fault}
#define FAULT4 FAULT, FAULT, FAULT, FAULT
__attribute__((section(".isr_vector"), used)) static const vector g_vectors[16 + LAST_IRQ + 1] = {
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
#ifdef SEMO_LINK
    {.handler = usart2}, /* 38 */
#endif
};
