//! The reference board: a NUCLEO-G474RE (STM32G474RE) wired as in `docs/hardware.md`.
//!
//! Everything that names a pin, a timer, a bus or an interrupt is here; the tasks only see the
//! small driver structs below. Another board is another file like this one plus a feature in
//! `Cargo.toml` (see `board/mod.rs`).
//!
//! | signal | pin | peripheral | note |
//! |---|---|---|---|
//! | H-bridge EN (PWM) | PA8 | TIM1_CH1, 20 kHz | DRV8874 in PH/EN mode; TIM1 is the drive timer |
//! | H-bridge PH (direction) | PA9 | GPIO out | |
//! | H-bridge nSLEEP | PA10 | GPIO out | low = bridge off (also at reset: board pull-down) |
//! | motor current (IPROPI) | PA0 | ADC1_IN1 | 1.5 kΩ to ground: 0.6825 V/A |
//! | crank encoder A / B | PB6 / PB7 | TIM4_CH1/CH2, encoder mode | 2048 lines, 8192 counts per turn |
//! | tilt servo | PB4 | TIM3_CH1, 50 Hz | 500–2500 µs over 270° |
//! | pendulum encoder SCK / MISO / MOSI | PB13 / PB14 / PB15 | SPI2, mode 1, 5.3 MHz | AS5047P, 14 bit |
//! | pendulum encoder CSn | PB12 | GPIO out | |
//! | emergency stop | PB1 | EXTI1, pull-up | normally-closed contact to GND: open = stop |
//! | laptop link TX / RX | PA2 / PA3 | USART2, 115200 8N1 | ST-LINK virtual COM port |
//! | (time driver) | — | TIM2 | `time-driver-tim2` in Cargo.toml |
//! | (control-loop executor) | — | UART4 interrupt | unused peripheral, its IRQ runs the executor |
//! | (configuration record) | — | flash page 0x0807_F800 | last 2 KiB page of bank 2 |

use embassy_stm32::adc::{Adc, AdcChannel, AdcConfig, AnyAdcChannel, SampleTime};
use embassy_stm32::exti::{self, ExtiInput};
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::gpio::{Level, Output, OutputType, Pull, Speed};
use embassy_stm32::interrupt::{self, InterruptExt, Priority};
use embassy_stm32::peripherals::{ADC1, IWDG, TIM1, TIM3, TIM4};
use embassy_stm32::spi::{self, Spi};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::qei::{self, Qei};
use embassy_stm32::timer::simple_pwm::{PwmPin, SimplePwm, SimplePwmChannel};
use embassy_stm32::usart::{self, BufferedUart};
use embassy_stm32::{bind_interrupts, peripherals, rcc, Config, Peri, Peripherals};
use static_cell::StaticCell;

pub const NAME: &str = "NUCLEO-G474RE";

bind_interrupts!(struct Irqs {
    USART2 => usart::BufferedInterruptHandler<peripherals::USART2>;
    EXTI1 => exti::InterruptHandler<interrupt::typelevel::EXTI1>;
});

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

/// SYSCLK = 170 MHz (the G474's maximum) from the internal 16 MHz HSI.
///
/// PLL: 16 MHz / 4 = 4 MHz input (allowed 2.66..16 MHz), × 85 = 340 MHz VCO (allowed
/// 96..344 MHz), / 2 on the R output = 170 MHz SYSCLK. Above 150 MHz the core regulator must be in
/// range 1 boost mode. AHB and both APBs run undivided at 170 MHz (all allow up to 170 MHz).
/// The HSI is used rather than the board's HSE so the firmware does not depend on the NUCLEO's
/// crystal/solder-bridge configuration. ADC1/2 run from SYSCLK (divided below 60 MHz by the
/// driver).
pub fn chip_config() -> Config {
    let mut config = Config::default();
    config.rcc.hsi = true;
    config.rcc.pll = Some(rcc::Pll {
        source: rcc::PllSource::HSI,
        prediv: rcc::PllPreDiv::DIV4,
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
/// 16-bit counter's wrap stays a whole number of turns.
pub const CRANK_COUNTS: u32 = 8192;
/// Motor current per ADC count (A): 3.3 V / 4096 / (455 µA/A · 1.5 kΩ), in I16F16 bits.
/// (DRV8874 datasheet: A_IPROPI = 455 µA/A typical.)
pub const AMPS_PER_COUNT_Q16: i32 = 77; // 3.3/4096/0.6825 A = 1.1805e-3 A → ·65536 = 77.4
/// Pendulum encoder: its count when the pendulum hangs at rest (θ = 0), and +1 if its count
/// grows counter-clockwise as seen from the front (SPEC §2), −1 if clockwise. Set when the magnet
/// is mounted (docs/hardware.md, "Calibration").
pub const PENDULUM_ZERO: u16 = 0;
pub const PENDULUM_SIGN: i8 = 1;
/// The flash page that holds the configuration record: offset from the flash base, and size.
/// `persist.x` asserts that the program image stays below it.
pub const CONFIG_PAGE_OFFSET: u32 = 0x7_F800;
pub const CONFIG_PAGE_SIZE: u32 = 2048;
/// Tilt servo: pulse width at the travel's two ends of its 270° range, and the angle θd (deg)
/// the middle of the range points the drive at.
pub const SERVO_MIN_US: u32 = 500;
pub const SERVO_MAX_US: u32 = 2500;
pub const SERVO_RANGE_DEG: f64 = 270.0;
pub const SERVO_CENTRE_DEG: f64 = 90.0;

/// The crank motor's hardware: H-bridge, encoder, current sense.
pub struct Drive {
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
    /// One conversion of the current sense (12-bit counts).
    pub fn current_counts(&mut self) -> u16 {
        self.adc
            .blocking_read(&mut self.sense, SampleTime::CYCLES24_5)
    }
}

/// The tilt servo's PWM.
pub struct Tilt {
    pwm: SimplePwmChannel<'static, TIM3>,
}

impl Tilt {
    /// Servo pulse width in µs (clamped to the servo's range).
    pub fn set_pulse_us(&mut self, us: u32) {
        let us = us.clamp(SERVO_MIN_US, SERVO_MAX_US);
        // 50 Hz: 20 000 µs per period.
        let max = self.pwm.max_duty_cycle();
        self.pwm.set_duty_cycle(us * max / 20_000);
    }
}

/// The pendulum encoder's bus.
pub struct PendulumBus {
    spi: Spi<'static, embassy_stm32::mode::Blocking, spi::mode::Master>,
    cs: Output<'static>,
}

impl PendulumBus {
    /// One 16-bit SPI frame, chip-select around it.
    pub fn transfer(&mut self, word: u16) -> Result<u16, spi::Error> {
        let mut w = [word];
        self.cs.set_low();
        let r = self.spi.blocking_transfer_in_place(&mut w);
        self.cs.set_high();
        r.map(|()| w[0])
    }
}

/// The safety task's inputs: the e-stop line and the independent watchdog.
pub struct SafetyIo {
    pub estop: ExtiInput<'static, embassy_stm32::mode::Async>,
    pub iwdg: Peri<'static, IWDG>,
}

impl SafetyIo {
    /// The e-stop is active: the normally-closed contact is open (pressed) or its wire is cut.
    pub fn estop_active(&self) -> bool {
        self.estop.is_high()
    }
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

/// Splits the chip's peripherals into the tasks' resources.
pub fn split(p: Peripherals) -> Board {
    // Drive: TIM1 CH1 PWM at 20 kHz (inaudible, well above the motor's electrical corner).
    let en_pin = PwmPin::new(p.PA8, OutputType::PushPull);
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
    let qcfg = qei::Config {
        auto_reload: (CRANK_COUNTS - 1) as u16,
        ..Default::default()
    };
    let encoder = Qei::new(p.TIM4, p.PB6, p.PB7, qcfg);
    let drive = Drive {
        en,
        phase: Output::new(p.PA9, Level::Low, Speed::Low),
        sleep: Output::new(p.PA10, Level::Low, Speed::Low),
        encoder,
        adc: Adc::new(p.ADC1, AdcConfig::default()),
        sense: p.PA0.degrade_adc(),
    };

    // Tilt servo: TIM3 CH1 at 50 Hz, centred.
    let servo_pin = PwmPin::new(p.PB4, OutputType::PushPull);
    let pwm = SimplePwm::new(
        p.TIM3,
        Some(servo_pin),
        None,
        None,
        None,
        Hertz(50),
        CountingMode::EdgeAlignedUp,
    );
    let mut ch = pwm.split().ch1;
    ch.enable();
    let mut tilt = Tilt { pwm: ch };
    tilt.set_pulse_us((SERVO_MIN_US + SERVO_MAX_US) / 2);

    // Pendulum encoder: AS5047P, SPI mode 1 (CPOL 0, CPHA 1), at most 10 MHz.
    let mut scfg = spi::Config::default();
    scfg.mode = spi::MODE_1;
    scfg.frequency = Hertz(5_000_000);
    let pendulum = PendulumBus {
        spi: Spi::new_blocking(p.SPI2, p.PB13, p.PB15, p.PB14, scfg),
        cs: Output::new(p.PB12, Level::High, Speed::VeryHigh),
    };

    let safety = SafetyIo {
        estop: ExtiInput::new(p.PB1, p.EXTI1, Pull::Up, Irqs),
        iwdg: p.IWDG,
    };

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
