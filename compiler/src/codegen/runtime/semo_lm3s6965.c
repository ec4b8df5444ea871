/* semo_lm3s6965.c: the board file of the `cortex-m` targets for the TI
 * Stellaris LM3S6965 (QEMU's `lm3s6965evb`, the Evalbot's family): the
 * vector table and reset code, SysTick as a tickless clock (it interrupts
 * only when the loop's next deadline comes, or every 1.3 s, its longest
 * period), UART0 as the trace's output and a wake-up source (a received
 * byte ends a sleep), and the exit (through semihosting when built with
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
#define UART_FR_RXFE (1u << 4)
#define UART0_IM REG(0x4000C038u)
#define UART0_ICR REG(0x4000C044u)
#define UART_IM_RX (1u << 4)
#define UART_IM_RT (1u << 6)
#define NVIC_ISER0 REG(0xE000E100u)
#define UART0_IRQ 5u
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)
#define ICSR REG(0xE000ED04u)
#define ICSR_PENDSTCLR (1u << 25)
#define ICSR_PENDSTSET (1u << 26)
/* SysTick counts down 24 bits: its longest period. */
#define SYSTICK_MAX_CYCLES (1u << 24)
#define CYCLES_PER_MS (SEMO_CPU_HZ / 1000u)

/* Its own section (lm3s6965.ld): zeroing .bss must not wipe the stack it runs on. */
__attribute__((section(".stack"))) static uint32_t g_stack[SEMO_STACK_BYTES / 4];
/* The clock: processor cycles since semo__board_init are `g_period_start`
 * (the cycles of the SysTick periods before the current one) plus what
 * SysTick counted down in the current period of `g_period` cycles. */
static volatile uint64_t g_period_start;
static volatile uint32_t g_period;
static volatile uint32_t g_uart_input; /* bytes received (and discarded) */

/* ---------------------------------------------------------------- board */

/* A new period of `cycles` from now (at most SYSTICK_MAX_CYCLES). */
static void start_period(uint32_t cycles)
{
    g_period = cycles;
    SYST_RVR = cycles - 1u;
    SYST_CVR = 0; /* clears the counter: it reloads from RVR at the next cycle */
}

void semo__board_init(void)
{
    g_period_start = 0;
    start_period(SYSTICK_MAX_CYCLES);
    SYST_CSR = 7u; /* processor clock, interrupt, enabled */
    UART0_IM = UART_IM_RX | UART_IM_RT;
    NVIC_ISER0 = 1u << UART0_IRQ;
}

/* Cycles counted in the current period: SysTick counts down from `g_period - 1`. */
static uint32_t cycles_in_period(void)
{
    uint32_t current = SYST_CVR;
    return current == 0 ? 0 : g_period - current;
}

static bool period_ended(void)
{
    return (ICSR & ICSR_PENDSTSET) != 0;
}

static uint64_t cycles_now(void)
{
    for (;;) {
        uint64_t start = g_period_start;
        uint32_t period = g_period;
        uint32_t counted = cycles_in_period();
        /* The counter may have restarted while its interrupt is not taken yet. */
        bool ended = period_ended();
        if (start == g_period_start) /* else the interrupt came between the reads */
            return ended ? start + period : start + counted;
    }
}

int64_t semo__board_now_ms(void)
{
    return (int64_t)(cycles_now() / CYCLES_PER_MS);
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

/* Sleeps until board time `deadline_ms` or an interrupt (a received byte),
 * whichever is first: SysTick's period is set to end at the deadline, so
 * nothing wakes the core in between. Returns at once when the deadline has
 * passed or a period just ended (the caller looks at the time again). */
void semo__board_sleep_until(int64_t deadline_ms)
{
    /* Masked from here to wfi: an interrupt that comes meanwhile stays
     * pending and ends the wfi at once instead of being slept through. */
    __asm__ volatile("cpsid i" ::: "memory");
    uint32_t period = g_period;
    uint32_t counted = cycles_in_period();
    uint64_t now = g_period_start + counted;
    /* INT64_MAX: no deadline (only an interrupt ends the sleep). */
    uint64_t deadline = deadline_ms >= INT64_MAX / CYCLES_PER_MS ? UINT64_MAX : (uint64_t)deadline_ms * CYCLES_PER_MS;
    if (!period_ended() && deadline > now) {
        uint64_t wait = deadline - now;
        g_period_start = now;
        start_period(wait < SYSTICK_MAX_CYCLES ? (uint32_t)wait : SYSTICK_MAX_CYCLES);
        if (period_ended()) {
            /* The old period ended between the reads and the restart: count
             * its rest here, not the new period in the interrupt. */
            ICSR = ICSR_PENDSTCLR;
            g_period_start += period - counted;
        }
        __asm__ volatile("wfi" ::: "memory");
    }
    __asm__ volatile("cpsie i" ::: "memory");
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
    g_period_start += g_period;
    /* The loop's sleep set a short period for its deadline: back to the
     * longest (the few cycles since the counter ended are not counted, so
     * the clock is never early). */
    if (g_period != SYSTICK_MAX_CYCLES)
        start_period(SYSTICK_MAX_CYCLES);
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
    {.handler = systick},
    /* External interrupts 0..4 (GPIO ports A to E) stay disabled. */
    {.handler = fault},
    {.handler = fault},
    {.handler = fault},
    {.handler = fault},
    {.handler = fault},
    {.handler = uart0},
};
