//! The AS5047P driver (`rig::as5047`) against the simulated chip (`simrig::sensor`): the frame
//! words, the one-frame pipeline and its timestamps, the error flag cleared by reading ERRFL,
//! diagnostics, and what a cut cable reads with and without the MISO pull-up.

use kapitza_core::rig::as5047::{
    self, As5047, FrameError, DIAG_EVERY, FAULT_AFTER, READ_ANGLE, READ_DIAAGC, READ_ERRFL,
};
use kapitza_core::rig::fixed::Angle;
use kapitza_core::simrig::sensor::{Chip, Line, DIAAGC_NO_MAGNET};

fn read(drv: &mut As5047, chip: &mut Chip, t: u32) -> as5047::Reading {
    drv.sample(t, |w| Ok::<u16, ()>(chip.frame(w)))
}

/// A driver whose pipeline is primed (the power-up frame), on a chip at `angle`.
fn primed(angle: u16) -> (As5047, Chip) {
    let mut chip = Chip::default();
    chip.angle = angle;
    let mut drv = As5047::new();
    let first = read(&mut drv, &mut chip, 0);
    assert_eq!(first.count, Err(FrameError::NotYet));
    (drv, chip)
}

#[test]
fn command_words_carry_the_read_bit_and_even_parity() {
    // Datasheet, "SPI Command Frame": bit 14 = 1 for a read, bit 15 even parity over 14..0.
    // ANGLECOM 0x3FFF: 0x7FFF has 15 ones → parity 1 → 0xFFFF (the datasheet's angle read).
    assert_eq!(READ_ANGLE, 0xFFFF);
    // ERRFL 0x0001: 0x4001 has 2 ones → parity 0.
    assert_eq!(READ_ERRFL, 0x4001);
    // DIAAGC 0x3FFC: 0x7FFC has 13 ones → parity 1 → 0xFFFC.
    assert_eq!(READ_DIAAGC, 0xFFFC);
}

#[test]
fn each_angle_is_the_previous_frames_and_carries_its_time() {
    let (mut drv, mut chip) = primed(100);
    // The answer at t = 100 is what the power-up frame (t = 0) latched.
    chip.angle = 200;
    let r = read(&mut drv, &mut chip, 100);
    assert_eq!((r.t_us, r.count), (0, Ok(100)));
    chip.angle = 300;
    let r = read(&mut drv, &mut chip, 200);
    assert_eq!((r.t_us, r.count), (100, Ok(200)));
    assert_eq!(drv.health().bad_run, 0);
}

#[test]
fn a_glitched_command_is_cleared_by_reading_errfl_in_the_same_sample() {
    let (mut drv, mut chip) = primed(10);
    for t in 1..5u32 {
        chip.angle = 10 + t as u16;
        read(&mut drv, &mut chip, t * 100);
    }
    // Noise flips a bit of the next command: the chip sets PARERR and every answer carries EF
    // until ERRFL is read (datasheet, "ERRFL": cleared by reading).
    chip.glitch_next_command = true;
    chip.angle = 20;
    let r = read(&mut drv, &mut chip, 500);
    assert_eq!(r.count, Ok(14), "the angle asked at t = 400 was intact");
    assert_eq!(chip.errfl(), 0x4, "PARERR set by the glitched frame");
    chip.angle = 21;
    let r = read(&mut drv, &mut chip, 600);
    // EF on the answer to the glitched command, and on the next one (the flag stays until ERRFL
    // is read): no angle this sample. The driver read ERRFL in the same sample, clearing it.
    assert_eq!(r.count, Err(FrameError::ErrorFlag));
    assert_eq!(chip.errfl(), 0, "ERRFL cleared by its read");
    assert!(drv.health().errors.parity);
    // The next sample has the angle asked for at the end of the last one (t = 600).
    chip.angle = 22;
    let r = read(&mut drv, &mut chip, 700);
    assert_eq!((r.t_us, r.count), (600, Ok(21)));
    assert_eq!(drv.health().bad_run, 0);
    // Without the ERRFL read the flag would stay: a driver that only ever sends ANGLECOM sees
    // EF on every later answer (the failure mode of reading the angle alone).
    let mut chip = Chip::default();
    chip.glitch_next_command = true;
    chip.frame(READ_ANGLE);
    for _ in 0..10 {
        assert_ne!(chip.frame(READ_ANGLE) & 0x4000, 0);
    }
}

#[test]
fn a_cut_cable_with_the_pull_up_fails_the_sensor_after_fault_after_samples() {
    let (mut drv, mut chip) = primed(42);
    read(&mut drv, &mut chip, 100);
    chip.line = Line::CutPulledUp;
    for k in 1..FAULT_AFTER {
        let r = read(&mut drv, &mut chip, 100 + 100 * u32::from(k));
        assert_eq!(r.count, Err(FrameError::ErrorFlag));
        assert!(!drv.health().failed(), "sample {k}");
    }
    read(&mut drv, &mut chip, 100_000);
    assert_eq!(drv.health().bad_run, FAULT_AFTER);
    assert!(drv.health().failed());
    // Reconnected: the next ERRFL read clears, angles come back, the run resets.
    chip.line = Line::Connected;
    for t in 0..3 {
        read(&mut drv, &mut chip, 200_000 + t);
    }
    assert!(!drv.health().failed());
}

#[test]
fn a_cut_cable_pulled_low_reads_as_a_valid_zero_which_is_why_miso_needs_its_pull_up() {
    // 0x0000: even parity, no EF, angle 0. No decoder can tell it from a sensor at count 0;
    // only the pull-up (docs/hardware.md) turns a cut cable into 0xFFFF.
    let (mut drv, mut chip) = primed(5000);
    chip.line = Line::CutPulledDown;
    for t in 1..100u32 {
        let r = read(&mut drv, &mut chip, t * 100);
        if t > 1 {
            assert_eq!(r.count, Ok(0));
        }
    }
    assert!(!drv.health().failed());
}

#[test]
fn magnet_loss_is_read_from_diaagc_at_power_up_and_every_diag_every_samples() {
    // Power-up: the first sample reads DIAAGC.
    let mut chip = Chip::default();
    chip.diagnostics = DIAAGC_NO_MAGNET;
    let mut drv = As5047::new();
    read(&mut drv, &mut chip, 0);
    let d = drv.health().diagnostics.expect("read at power-up");
    assert!(d.magnet_low && !d.magnet_ok());
    assert_eq!(d.agc, 255);
    assert!(drv.health().failed());
    // A healthy start; the magnet falls off later and is seen within DIAG_EVERY samples.
    let (mut drv, mut chip) = primed(7);
    assert!(drv.health().diagnostics.unwrap().magnet_ok());
    assert!(drv.health().diagnostics.unwrap().ready);
    chip.diagnostics = DIAAGC_NO_MAGNET;
    let mut seen = None;
    for k in 1..=u32::from(DIAG_EVERY) + 1 {
        let r = read(&mut drv, &mut chip, k * 100);
        assert!(r.count.is_ok(), "a diagnostics read costs no angle");
        if drv.health().failed() {
            seen = Some(k);
            break;
        }
    }
    assert!(
        seen.is_some_and(|k| k <= u32::from(DIAG_EVERY) + 1),
        "{seen:?}"
    );
}

#[test]
fn impossible_register_contents_are_bus_errors() {
    // DIAAGC with MAGL and MAGH together (the field cannot be too low and too high at once).
    let (mut drv, mut chip) = primed(7);
    let healthy = drv.health().diagnostics;
    chip.diagnostics = 0x0C00;
    let mut asked = 0;
    for k in 1..=u32::from(DIAG_EVERY) + 1 {
        drv.sample(k * 100, |w| {
            asked += u32::from(w == READ_DIAAGC);
            Ok::<u16, ()>(chip.frame(w))
        });
    }
    assert_eq!(asked, 1, "DIAAGC read once in DIAG_EVERY samples");
    assert_eq!(
        drv.health().diagnostics,
        healthy,
        "no diagnostics taken from an impossible word"
    );
}

#[test]
fn angle_applies_zero_and_sign() {
    // count − zero in 2^-14 turn, as 2^-32 turn: · 2^18.
    assert_eq!(as5047::angle(100, 100, 1), Angle::ZERO);
    assert_eq!(as5047::angle(101, 100, 1).to_turns_u32(), 1 << 18);
    assert_eq!(
        as5047::angle(99, 100, 1).to_turns_u32(),
        0u32.wrapping_sub(1 << 18)
    );
    assert_eq!(
        as5047::angle(101, 100, -1).to_turns_u32(),
        0u32.wrapping_sub(1 << 18)
    );
    // A quarter turn: 4096 counts.
    assert_eq!(as5047::angle(4096, 0, 1).to_turns_u32(), 1 << 30);
}
