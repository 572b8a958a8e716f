//! The reference board: a NUCLEO-G474RE (STM32G474RE) wired as in `docs/hardware.md`.
//!
//! Everything that names a pin, a timer, a bus or an interrupt is here; the tasks only see the
//! small driver structs below. Another board is another file like this one plus a feature in
//! `Cargo.toml` (see `board/mod.rs`).
//!
//! | signal | pin | peripheral | note |
//! |---|---|---|---|
//! | H-bridge EN (PWM) | PA8 | TIM1_CH1, 20 kHz, speed Low | DRV8874 in PH/EN mode; TIM1 is the drive timer |
//! | H-bridge PH (direction) | PA9 | GPIO out, speed Low | |
//! | H-bridge nSLEEP | PA10 | GPIO out | low = bridge off (also at reset: board pull-down) |
//! | H-bridge nFAULT | PA6 | TIM1_BKIN (AF6) | open drain, pulled up: low = fault, TIM1 break (outputs off in hardware) |
//! | motor current (IPROPI) | PA0 | ADC1_IN1 | 1.5 kΩ to ground: 0.6825 V/A |
//! | crank encoder A / B | PB6 / PB7 | TIM4_CH1/CH2, encoder mode, input filter 282 ns | 2048 lines, 8192 counts per turn |
//! | tilt servo | PC6 (CN10 pin 4) | TIM3_CH1 (AF2), 50 Hz, speed Low | pulse map from the calibration (reference: 500–2500 µs over 270°); no pull at reset |
//! | pendulum encoder SCK / MISO / MOSI | PB13 / PB14 / PB15 | SPI2, mode 1, 5.3 MHz, speed Medium | AS5047P, 14 bit; MISO pulled up (a cut cable reads 0xFFFF) |
//! | pendulum encoder CSn | PB12 | GPIO out, speed Medium | setup, hold and high time from the cycle counter |
//! | emergency stop | PB1 | GPIO in, pull-up (+ external 4.7 kΩ and RC) | normally-closed contact to GND: open = stop; read at every control tick |
//! | laptop link TX / RX | PA2 / PA3 | USART2, 115200 8N1 | ST-LINK virtual COM port |
//! | (time driver) | — | TIM2 | `time-driver-tim2` in Cargo.toml |
//! | (control-loop executor) | — | UART4 interrupt | unused peripheral, its IRQ runs the executor |
//! | (configuration record) | — | flash 0x0807_F000..0x0808_0000 | last two 2 KiB pages of bank 2 |

use embassy_stm32::adc::{Adc, AdcChannel, AdcConfig, AnyAdcChannel, SampleTime};
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::gpio::{Input, Level, Output, OutputType, Pull, Speed};
use embassy_stm32::interrupt::{self, InterruptExt, Priority};
use embassy_stm32::pac::timer::vals::{Bkp, FilterValue, Ossi};
use embassy_stm32::peripherals::{ADC1, IWDG, PA6, TIM1, TIM3, TIM4};
use embassy_stm32::spi::{self, Spi};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::qei::{self, Qei};
use embassy_stm32::timer::simple_pwm::{PwmPin, PwmPinConfig, SimplePwm, SimplePwmChannel};
use embassy_stm32::usart::{self, BufferedUart};
use embassy_stm32::{bind_interrupts, pac, peripherals, rcc, Config, Peri, Peripherals};
use static_cell::StaticCell;

pub const NAME: &str = "NUCLEO-G474RE";

bind_interrupts!(struct Irqs {
    USART2 => LineErrors, usart::BufferedInterruptHandler<peripherals::USART2>;
});

/// Runs before embassy's buffered-UART handler on USART2's interrupt and passes a parity,
/// framing, noise or overrun flag on as a line error. embassy-stm32 0.6's handler only logs
/// these flags and clears them (its `read` never returns an error), so without this the rig
/// would never hear of them. Reading ISR changes nothing; embassy clears the flags through
/// ICR right after.
pub struct LineErrors;

impl interrupt::typelevel::Handler<interrupt::typelevel::USART2> for LineErrors {
    unsafe fn on_interrupt() {
        let isr = pac::USART2.isr().read();
        if isr.pe() || isr.fe() || isr.ne() || isr.ore() {
            crate::channels::LINE_ERROR.signal(());
        }
    }
}

/// The interrupt that runs the control loop's executor (UART4 is not used on this board), and
/// its priority: above the thread-mode tasks, below the time driver and USART2.
pub const CONTROL_IRQ: interrupt::Interrupt = interrupt::Interrupt::UART4;
pub const CONTROL_PRIORITY: Priority = Priority::P6;

#[allow(non_snake_case)]
#[embassy_stm32::interrupt]
unsafe fn UART4() {
    // SAFETY: called only from this interrupt's handler, after `start` (main.rs).
    unsafe { crate::CONTROL_EXECUTOR.on_interrupt() }
}

/// Chip-select setup and hold around an AS5047P frame, and its high time between frames: the
/// datasheet's tL, tH and tCSn are ≥ 350 ns ("SPI Timing"), 60 cycles at 170 MHz (352 ns),
/// counted on DWT's cycle counter. (`cortex_m::asm::delay` counts loop iterations, whose cycles
/// depend on the flash wait states and the ART cache: ~3× the budget here.)
const CS_CYCLES: u32 = 60;

/// Busy-waits at least `cycles` core clock cycles on DWT CYCCNT (started in [`split`]); the
/// wrapping difference stays right across the counter's 25 s wrap.
fn wait_cycles(cycles: u32) {
    let start = cortex_m::peripheral::DWT::cycle_count();
    while cortex_m::peripheral::DWT::cycle_count().wrapping_sub(start) < cycles {}
}

/// Starts DWT's cycle counter: trace enabled in DEMCR (TRCENA), then CYCCNTENA.
fn start_cycle_counter() {
    // SAFETY: only DEMCR.TRCENA and DWT_CTRL.CYCCNTENA are set, once at boot before any task
    // runs; nothing else in the firmware owns DCB or DWT (a debugger also sets TRCENA).
    let mut cp = unsafe { cortex_m::Peripherals::steal() };
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();
}

/// SYSCLK = 170 MHz (the G474's maximum) from the board's 24 MHz crystal X3 (HSE).
///
/// Why the crystal: the HSI is ±1 % over temperature (STM32G474 datasheet, "HSI16"), and the
/// drive's ω is counted in this clock, so R ∝ ω² would be off by up to ±2 %; a crystal is tens
/// of ppm. The NUCLEO-G474RE (MB1367) carries X3 = 24 MHz fitted and wired to OSC_IN/OSC_OUT by
/// default (docs/hardware.md, "Clock", for the sources). HSE in oscillator mode (HSEBYP = 0),
/// not bypass: it is a crystal, not the ST-LINK's MCO.
///
/// PLL: 24 MHz / 6 = 4 MHz input (allowed 2.66..16 MHz), × 85 = 340 MHz VCO (allowed
/// 96..344 MHz), / 2 on the R output = 170 MHz SYSCLK. Above 150 MHz the core regulator must be in
/// range 1 boost mode. AHB and both APBs run undivided at 170 MHz (all allow up to 170 MHz).
/// ADC1/2 run from SYSCLK (divided below 60 MHz by the driver). embassy-stm32 waits for HSERDY
/// before anything else runs: a board without its crystal hangs here, before the watchdog
/// starts, with the bridge asleep (nSLEEP has its pull-down) — the bring-up checklist's first
/// step shows it.
pub fn chip_config() -> Config {
    let mut config = Config::default();
    config.rcc.hse = Some(rcc::Hse {
        freq: Hertz(24_000_000),
        mode: rcc::HseMode::Oscillator,
    });
    config.rcc.pll = Some(rcc::Pll {
        source: rcc::PllSource::HSE,
        prediv: rcc::PllPreDiv::DIV6,
        mul: rcc::PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(rcc::PllRDiv::DIV2),
    });
    config.rcc.sys = rcc::Sysclk::PLL1_R;
    config.rcc.ahb_pre = rcc::AHBPrescaler::DIV1;
    config.rcc.apb1_pre = rcc::APBPrescaler::DIV1;
    config.rcc.apb2_pre = rcc::APBPrescaler::DIV1;
    config.rcc.boost = true;
    config.rcc.mux.adc12sel = rcc::mux::Adcsel::SYS;
    config
}

/// Crank encoder counts per turn (4 × 2048 lines). A power of two that divides 2^16, so the
/// 16-bit counter's wrap stays a whole number of turns. (The bench's measured constants — the
/// pendulum sensor's zero and sign, the crank's sign, the servo's pulse map, the current
/// sense's offset and gain — are not build constants: they are the configuration's
/// calibration, set over the link and stored in flash.)
pub const CRANK_COUNTS: u32 = 8192;
/// The flash area that holds the configuration records, two 2 KiB pages
/// (`kapitza_core::persist::store`): offset from the flash base, and size of both.
/// `persist.x` asserts that the program image stays below it.
pub const CONFIG_PAGE_OFFSET: u32 = 0x7_F000;
pub const CONFIG_PAGE_SIZE: u32 = 4096;
/// The widest pulse range any servo calibration may ask for (µs): the configuration's own
/// range is checked when it is set (`kapitza_core::rig::calibration`), this is the board's last
/// word.
const SERVO_MIN_US: f64 = 400.0;
const SERVO_MAX_US: f64 = 2600.0;

/// The crank motor's hardware: H-bridge, encoder, current sense, and the e-stop line read at
/// each control tick.
pub struct Drive {
    estop: Input<'static>,
    en: SimplePwmChannel<'static, TIM1>,
    phase: Output<'static>,
    sleep: Output<'static>,
    encoder: Qei<'static, TIM4>,
    adc: Adc<'static, ADC1>,
    sense: AnyAdcChannel<'static, ADC1>,
}

impl Drive {
    /// H-bridge command: `duty` in [−32768, 32767] (I1F15 bits); the sign sets the direction.
    pub fn set_duty(&mut self, duty: i16) {
        let max = self.en.max_duty_cycle();
        let mag = u32::from(duty.unsigned_abs()).min(32_767);
        self.phase
            .set_level(if duty < 0 { Level::Low } else { Level::High });
        self.en.set_duty_cycle(mag * max / 32_768);
    }
    /// Wake the bridge (true) or put it to sleep, outputs off (false).
    pub fn enable(&mut self, on: bool) {
        self.sleep
            .set_level(if on { Level::High } else { Level::Low });
    }
    /// The encoder count in [0, CRANK_COUNTS).
    pub fn crank_count(&self) -> u32 {
        u32::from(self.encoder.count()) % CRANK_COUNTS
    }
    /// The e-stop is active: the normally-closed contact is open (pressed) or its wire is cut.
    pub fn estop_active(&self) -> bool {
        self.estop.is_high()
    }
    /// One conversion of the current sense (12-bit counts).
    pub fn current_counts(&mut self) -> u16 {
        self.adc
            .blocking_read(&mut self.sense, SampleTime::CYCLES24_5)
    }
    /// nFAULT (PA6) reads low. GPIOA_IDR follows the pin in its alternate function too.
    pub fn nfault_low(&self) -> bool {
        pac::GPIOA.idr().read().idr(6) == pac::gpio::vals::Idr::LOW
    }
    /// TIM1_SR.BIF: the break input (nFAULT) cut the outputs since the flag was last cleared.
    pub fn break_flag(&self) -> bool {
        pac::TIM1.sr().read().bif(0)
    }
    /// Clears BIF and sets MOE again: the outputs follow the PWM. While nFAULT is low the break
    /// input keeps MOE cleared and BIF set; the rig loop asks only while it reads high.
    pub fn rearm(&mut self) {
        // SR's flags are cleared by writing 0 (rc_w0) and kept by writing 1: one write clears
        // BIF alone, without a read-modify-write racing the other flags.
        let mut sr = pac::timer::regs::SrAdv(u32::MAX);
        sr.set_bif(0, false);
        pac::TIM1.sr().write_value(sr);
        pac::TIM1.bdtr().modify(|w| w.set_moe(true));
    }
}

/// The tilt servo's PWM.
pub struct Tilt {
    pwm: SimplePwmChannel<'static, TIM3>,
}

impl Tilt {
    /// Servo pulse width in µs (clamped to what any servo takes); the first call starts the
    /// pulses.
    pub fn set_pulse_us(&mut self, us: f64) {
        let us = us.clamp(SERVO_MIN_US, SERVO_MAX_US);
        // 50 Hz: 20 000 µs per period, in the timer's counts (rounded).
        let max = f64::from(self.pwm.max_duty_cycle());
        self.pwm.set_duty_cycle((us * max / 20_000.0 + 0.5) as u32);
        self.pwm.enable();
    }
}

/// The pendulum encoder's bus.
pub struct PendulumBus {
    spi: Spi<'static, embassy_stm32::mode::Blocking, spi::mode::Master>,
    cs: Output<'static>,
}

impl PendulumBus {
    /// One 16-bit SPI frame, chip-select around it with the sensor's setup, hold and
    /// high times.
    pub fn transfer(&mut self, word: u16) -> Result<u16, spi::Error> {
        let mut w = [word];
        self.cs.set_low();
        wait_cycles(CS_CYCLES);
        let r = self.spi.blocking_transfer_in_place(&mut w);
        wait_cycles(CS_CYCLES);
        self.cs.set_high();
        wait_cycles(CS_CYCLES);
        r.map(|()| w[0])
    }
}

/// TIM1's break input on PA6 (AF6), wired to the DRV8874's nFAULT: a bridge fault (over-current,
/// over-temperature, under-voltage) clears MOE in hardware within a few clock cycles, forcing the
/// PWM pin to its idle level (low) whatever the software does. Active low, filtered over 8 clock
/// samples (47 ns) against glitches; no automatic re-enable (AOE = 0): the rig loop reads BIF and
/// the pin at every control tick and re-arms through [`Drive::rearm`] (`kapitza_core::rig::bridge`).
/// The pin is taken from `Peripherals` so nothing else can claim it.
fn arm_break_input(_nfault: Peri<'static, PA6>) {
    let pa = pac::GPIOA;
    pa.pupdr()
        .modify(|w| w.set_pupdr(6, pac::gpio::vals::Pupdr::PULL_UP));
    pa.afr(0).modify(|w| w.set_afr(6, 6));
    pa.moder()
        .modify(|w| w.set_moder(6, pac::gpio::vals::Moder::ALTERNATE));
    pac::TIM1.af1().modify(|w| w.set_bkine(true));
    pac::TIM1.bdtr().modify(|w| {
        w.set_ossi(Ossi::IDLE_LEVEL);
        w.set_bkf(0, FilterValue::FCK_INT_N8);
        w.set_bkp(0, Bkp::ACTIVE_LOW);
        w.set_aoe(false);
        w.set_bke(0, true);
    });
}

/// The watchdog, for the safety task.
pub struct SafetyIo {
    pub iwdg: Peri<'static, IWDG>,
}

/// Every task's share of the chip.
pub struct Board {
    pub drive: Drive,
    pub tilt: Tilt,
    pub pendulum: PendulumBus,
    pub safety: SafetyIo,
    pub uart: BufferedUart<'static>,
    pub flash: Flash<'static, Blocking>,
}

/// Crank encoder input filter (TIM4 CCMR1 IC1F/IC2F): fDTS/8 sampled 6 times, 48 cycles at
/// 170 MHz = 282 ns. The fastest legitimate edges come at the range table's top ω (1000 rad/s,
/// `kapitza_core::rig::fields`): 159 rev/s × 8192 counts = 1.30 M counts/s, so one channel
/// holds each level for 2 counts = 1.53 µs, or 1.15 µs with an encoder's ±45° duty error. The
/// filter passes those with a factor 4 to spare and rejects shorter spikes (the motor's
/// commutation, the bridge's 20 kHz switching edges); it delays both channels alike, by
/// 282–329 ns, so no count is lost or reordered. The next step, fDTS/8 × 8 (376 ns), leaves
/// a factor 3; fDTS/16 × 8 (753 ns) would eat the duty error's margin.
const ENCODER_FILTER: FilterValue = FilterValue::FDTS_DIV8_N6;

/// Splits the chip's peripherals into the tasks' resources.
pub fn split(p: Peripherals) -> Board {
    start_cycle_counter();
    // Drive: TIM1 CH1 PWM at 20 kHz (inaudible, well above the motor's electrical corner).
    // Speed Low (OSPEEDR 00, rated to 5 MHz into 50 pF: STM32G474 datasheet, "I/O AC
    // characteristics"): 250 times the 20 kHz PWM, and the DRV8874's own output edges are far
    // slower than the pin's. Slow edges on the cable to the bridge couple less into the
    // encoder and sensor lines beside it. `PwmPin::new` would set VeryHigh.
    let en_pin = PwmPin::new_with_config(
        p.PA8,
        PwmPinConfig {
            output_type: OutputType::PushPull,
            speed: Speed::Low,
            pull: Pull::None,
        },
    );
    let pwm = SimplePwm::new(
        p.TIM1,
        Some(en_pin),
        None,
        None,
        None,
        Hertz(20_000),
        CountingMode::EdgeAlignedUp,
    );
    let mut en = pwm.split().ch1;
    en.set_duty_cycle(0);
    en.enable();
    arm_break_input(p.PA6);
    let qcfg = qei::Config {
        auto_reload: (CRANK_COUNTS - 1) as u16,
        ..Default::default()
    };
    let encoder = Qei::new(p.TIM4, p.PB6, p.PB7, qcfg);
    // `Qei::new` leaves IC1F/IC2F at 0 (no filter); the filter is set before the first count.
    pac::TIM4.ccmr_input(0).modify(|w| {
        w.set_icf(0, ENCODER_FILTER);
        w.set_icf(1, ENCODER_FILTER);
    });
    let drive = Drive {
        estop: Input::new(p.PB1, Pull::Up),
        en,
        // PH changes only with the duty's sign: the slowest edges.
        phase: Output::new(p.PA9, Level::Low, Speed::Low),
        sleep: Output::new(p.PA10, Level::Low, Speed::Low),
        encoder,
        adc: Adc::new(p.ADC1, AdcConfig::default()),
        sense: p.PA0.degrade_adc(),
    };

    // Tilt servo: TIM3 CH1 at 50 Hz, no pulses until the control loop names its first θd (a
    // pulse now would swing the mount: `kapitza_core::rig::servo`). On PC6 (AF2), which is an
    // analog input with no pull from reset until here: PB4, TIM3_CH1's other pin, is NJTRST
    // with its pull-up on at reset, so the servo would see a high line through every reset.
    // Speed Low: a 500–2500 µs pulse needs no fast edge.
    let servo_pin = PwmPin::new_with_config(
        p.PC6,
        PwmPinConfig {
            output_type: OutputType::PushPull,
            speed: Speed::Low,
            pull: Pull::None,
        },
    );
    let pwm = SimplePwm::new(
        p.TIM3,
        Some(servo_pin),
        None,
        None,
        None,
        Hertz(50),
        CountingMode::EdgeAlignedUp,
    );
    let tilt = Tilt {
        pwm: pwm.split().ch1,
    };

    // Pendulum encoder: AS5047P, SPI mode 1 (CPOL 0, CPHA 1), at most 10 MHz.
    let mut scfg = spi::Config::default();
    scfg.mode = spi::MODE_1;
    scfg.frequency = Hertz(5_000_000);
    scfg.miso_pull = Pull::Up;
    // SCK, MOSI and CSn at speed Medium (OSPEEDR 01, rated to 25 MHz into 50 pF: STM32G474
    // datasheet, "I/O AC characteristics"), 5 times the 5.3 MHz clock; Low is rated to 5 MHz,
    // at the clock itself. embassy's default, VeryHigh, rings on 30 cm of cable for no gain.
    scfg.gpio_speed = Speed::Medium;
    let pendulum = PendulumBus {
        spi: Spi::new_blocking(p.SPI2, p.PB13, p.PB15, p.PB14, scfg),
        cs: Output::new(p.PB12, Level::High, Speed::Medium),
    };

    let safety = SafetyIo { iwdg: p.IWDG };

    // Laptop link on the ST-LINK's virtual COM port.
    static TX_BUF: StaticCell<[u8; 512]> = StaticCell::new();
    static RX_BUF: StaticCell<[u8; 256]> = StaticCell::new();
    let mut ucfg = usart::Config::default();
    ucfg.baudrate = kapitza_core::link::BAUD;
    let uart = defmt::unwrap!(BufferedUart::new(
        p.USART2,
        p.PA3,
        p.PA2,
        TX_BUF.init([0; 512]),
        RX_BUF.init([0; 256]),
        Irqs,
        ucfg,
    ));

    interrupt::UART4.set_priority(CONTROL_PRIORITY);

    Board {
        drive,
        tilt,
        pendulum,
        safety,
        uart,
        flash: Flash::new_blocking(p.FLASH),
    }
}
