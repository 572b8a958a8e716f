//! The H-bridge's supply and fault lines as the firmware sees them: the DRV8874's under-voltage
//! lockout on nFAULT, and TIM1's break input that nFAULT drives.
//!
//! ```text
//! VM = 0 while the e-stop is pressed (its first contact opens the relay), else the supply
//! nFAULT low  ⇔  awake (nSLEEP high) and VM below UVLO_V   (asleep, the chip drives nothing)
//! nFAULT low  →  BIF set, MOE cleared, at once and until re-armed (AOE = 0)
//! outputs drive the motor only while awake, MOE set and VM at or above UVLO_V
//! rearm: BIF cleared, MOE set — both set again at once while nFAULT stays low
//! ```
//! A supply that sags below `UVLO_V` under load does the same as the relay ([`Bridge::supply_v`]).

/// The DRV8874's lowest supply for normal operation (V): below it the under-voltage lockout
/// disables the outputs and pulls nFAULT low (DRV8874 datasheet, "Recommended Operating
/// Conditions", VVM 4.5–37 V; "VM Supply Undervoltage Lockout").
pub const UVLO_V: f64 = 4.5;

/// The bridge and TIM1's break, as a bench has them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bridge {
    /// The bench supply ahead of the e-stop's relay (V): 12 V, or a sag.
    pub supply_v: f64,
    /// nSLEEP as the firmware drives it.
    awake: bool,
    /// VM reaches the bridge (the relay closed: the e-stop released).
    relay_closed: bool,
    /// TIM1_SR.BIF and TIM1_BDTR.MOE.
    break_flag: bool,
    moe: bool,
}

impl Default for Bridge {
    fn default() -> Self {
        Self::new(12.0)
    }
}

impl Bridge {
    /// A bench on `supply_v`, the bridge asleep, the outputs armed (as `SimplePwm::new` leaves
    /// MOE).
    pub const fn new(supply_v: f64) -> Self {
        Self {
            supply_v,
            awake: false,
            relay_closed: true,
            break_flag: false,
            moe: true,
        }
    }

    /// VM at the bridge (V).
    pub fn vm(&self) -> f64 {
        if self.relay_closed {
            self.supply_v
        } else {
            0.0
        }
    }

    /// nFAULT reads low.
    pub fn nfault_low(&self) -> bool {
        self.awake && self.vm() < UVLO_V
    }

    /// TIM1's break flag.
    pub fn break_flag(&self) -> bool {
        self.break_flag
    }

    /// One instant: the e-stop (`pressed` opens the relay); the break input acts on nFAULT as
    /// it reads now.
    pub fn update(&mut self, pressed: bool) {
        self.relay_closed = !pressed;
        if self.nfault_low() {
            self.break_flag = true;
            self.moe = false;
        }
    }

    /// nSLEEP as the firmware drives it from now on.
    pub fn set_awake(&mut self, awake: bool) {
        self.awake = awake;
        self.update(!self.relay_closed);
    }

    /// The outputs drive the motor.
    pub fn driving(&self) -> bool {
        self.awake && self.moe && self.vm() >= UVLO_V
    }

    /// Clears BIF and sets MOE; the break input sets BIF and clears MOE again while nFAULT
    /// stays low.
    pub fn rearm(&mut self) {
        self.break_flag = false;
        self.moe = true;
        self.update(!self.relay_closed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_relay_trips_the_break_until_rearmed() {
        let mut b = Bridge::default();
        b.set_awake(true);
        assert!(b.driving() && !b.nfault_low());
        // E-stop: VM gone, nFAULT low, break: outputs off.
        b.update(true);
        assert!(b.nfault_low() && b.break_flag() && !b.driving());
        // Re-arming while nFAULT is low changes nothing.
        b.rearm();
        assert!(b.break_flag() && !b.driving());
        // Asleep, nFAULT is released; released e-stop: VM back, but MOE stays off.
        b.set_awake(false);
        assert!(!b.nfault_low());
        b.update(false);
        b.set_awake(true);
        assert!(!b.nfault_low() && b.break_flag() && !b.driving());
        b.rearm();
        assert!(!b.break_flag() && b.driving());
        // A sag below UVLO does the same as the relay.
        b.supply_v = 4.0;
        b.update(false);
        assert!(b.nfault_low() && !b.driving());
    }
}
