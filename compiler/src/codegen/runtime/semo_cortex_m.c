/* semo_cortex_m.c: what every `cortex-m` board shares, being the core's:
 * the reset code (.data copied, .bss zeroed, then main), the mission clock
 * and the sleep on SysTick as a tickless clock (it interrupts only when the
 * loop's next deadline comes, or after its longest period: 2^24 cycles),
 * the exit (through semihosting when built with -DSEMO_SEMIHOSTING, so that
 * a QEMU run ends; on a board the robot halts) and the fault handler. The
 * board file (its start-up file, named by the platform table) has the stack,
 * the serial port and the vector table, which names semo__reset,
 * semo__systick and semo__fault, and starts the clock with
 * semo__systick_start; SEMO_CPU_HZ, the core clock SysTick counts, comes
 * from the table through the Makefile. Linked with the board's script
 * (board.ld.in), which gives the symbols of .data and .bss; no C library
 * start-up files (-nostartfiles).
 */
#include "semo_internal.h"
#ifdef SEMO_LINK
#include "semo_link.h"
#endif

#include <stddef.h>
#include <string.h>

#ifndef SEMO_CPU_HZ
#error "SEMO_CPU_HZ: the core clock, from the board's Makefile"
#endif

#define REG(addr) (*(volatile uint32_t *)(addr))
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)
#define ICSR REG(0xE000ED04u)
#define ICSR_PENDSTCLR (1u << 25)
#define ICSR_PENDSTSET (1u << 26)
/* The shortest sleep: SysTick's reload value is the period less one, and
 * a reload value of 0 disables it. */
#define MIN_SLEEP_CYCLES 2u
/* SysTick counts down 24 bits: its longest period. */
#define SYSTICK_MAX_CYCLES (1u << 24)
#define CYCLES_PER_MS (SEMO_CPU_HZ / 1000u)

/* The clock: processor cycles since semo__systick_start are `g_period_start`
 * (the cycles of the SysTick periods before the current one) plus what
 * SysTick counted down in the current period of `g_period` cycles. */
static volatile uint64_t g_period_start;
static volatile uint32_t g_period;

#ifdef SEMO_LINK
volatile bool semo__board_woken;

/* Received on the link, from the board's interrupt (which alone moves
 * `head`) to the loop (which alone moves `tail`): twice the longest frame. */
#define RX_RING (2u * SEMO_LINK_WIRE_MAX)
static volatile unsigned char g_rx[RX_RING];
static volatile uint32_t g_rx_head, g_rx_tail;
static volatile unsigned long g_rx_overruns;

/* A full ring loses the byte (counted): the frame it was in fails its CRC,
 * goes unacknowledged and comes again. */
void semo__board_link_received(unsigned char byte)
{
    uint32_t next = (g_rx_head + 1u) % RX_RING;
    if (next == g_rx_tail) {
        g_rx_overruns++;
    } else {
        g_rx[g_rx_head] = byte;
        g_rx_head = next;
    }
    semo__board_woken = true;
}

bool semo__board_link_peek(unsigned char *byte)
{
    if (g_rx_tail == g_rx_head)
        return false;
    *byte = g_rx[g_rx_tail];
    return true;
}

void semo__board_link_take(void)
{
    if (g_rx_tail != g_rx_head)
        g_rx_tail = (g_rx_tail + 1u) % RX_RING;
}

unsigned long semo__board_link_overruns(void)
{
    return g_rx_overruns;
}
#endif

/* A new period of `cycles` from now (at most SYSTICK_MAX_CYCLES). */
static void start_period(uint32_t cycles)
{
    g_period = cycles;
    SYST_RVR = cycles - 1u;
    SYST_CVR = 0; /* clears the counter: it reloads from RVR at the next cycle */
}

void semo__systick_start(void)
{
    g_period_start = 0;
    start_period(SYSTICK_MAX_CYCLES);
    SYST_CSR = 7u; /* processor clock, interrupt, enabled */
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

/* Sleeps until board time `deadline_ms` or an interrupt (a received byte),
 * whichever is first: SysTick's period is set to end at the deadline, so
 * nothing wakes the core in between. Returns at once when the deadline has
 * passed or a period just ended (the caller looks at the time again). */
void semo__board_sleep_until(int64_t deadline_ms)
{
    /* Masked from here to wfi: an interrupt that comes meanwhile stays
     * pending and ends the wfi at once instead of being slept through. */
    __asm__ volatile("cpsid i" ::: "memory");
#ifdef SEMO_LINK
    /* A byte came on the link since the last sleep: the loop reads it first. */
    if (semo__board_woken) {
        semo__board_woken = false;
        __asm__ volatile("cpsie i" ::: "memory");
        return;
    }
#endif
    uint32_t period = g_period;
    uint32_t counted = cycles_in_period();
    uint64_t now = g_period_start + counted;
    /* INT64_MAX: no deadline (only an interrupt ends the sleep). */
    uint64_t deadline = deadline_ms >= INT64_MAX / CYCLES_PER_MS ? UINT64_MAX : (uint64_t)deadline_ms * CYCLES_PER_MS;
    /* A period of one cycle would be a reload value of 0, which stops
     * SysTick for good (the clock would stand still and the sleep never
     * end): a deadline closer than MIN_SLEEP_CYCLES is waited for awake,
     * the caller looking at the time again. */
    if (!period_ended() && deadline > now && deadline - now >= MIN_SLEEP_CYCLES) {
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

void semo__systick(void)
{
    g_period_start += g_period;
    /* The loop's sleep set a short period for its deadline: back to the
     * longest (the few cycles since the counter ended are not counted, so
     * the clock is never early). */
    if (g_period != SYSTICK_MAX_CYCLES)
        start_period(SYSTICK_MAX_CYCLES);
}

/* ------------------------------------------------------------- start-up */

int main(int argc, char **argv);

extern uint32_t _sidata[], _sdata[], _edata[], _sbss[], _ebss[];

void semo__reset(void)
{
    memcpy(_sdata, _sidata, (size_t)((char *)_edata - (char *)_sdata));
    memset(_sbss, 0, (size_t)((char *)_ebss - (char *)_sbss));
    semo__board_exit(main(0, NULL));
}

#ifdef SEMO_LINK
/* No heap: newlib-nano's printf family (a heartbeat's text, formatted with
 * snprintf by the generated control task) links malloc for its own
 * buffers, which a string's formatting never asks for. Every request for
 * heap memory fails here, so none is ever taken from the stack's RAM. */
void *_sbrk(ptrdiff_t increment);
void *_sbrk(ptrdiff_t increment)
{
    (void)increment;
    return (void *)-1;
}
#endif

/* A fault or an unexpected interrupt: the program cannot go on. */
void semo__fault(void)
{
    static const char message[] = "semo runtime: fault\n";
    semo__board_put(NULL, message, sizeof message - 1);
    semo__board_exit(1);
}
