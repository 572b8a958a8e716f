//! The laptop link on USART2 (the ST-LINK's virtual COM port): bytes in, bytes out.
//!
//! Framing, decoding, answers, telemetry and the version policy all live in the control loop's
//! `kapitza_core::station::RigLoop`; this task only moves bytes between the UART and the two
//! pipes; the task never stops. Line errors reach the rig loop as `LINE_ERROR` (which drops the
//! partial frame and counts it in `frames_bad`) from two places: the UART's parity, framing,
//! noise and overrun flags (`board::LineErrors`, on USART2's interrupt: embassy-stm32 0.6's
//! buffered UART only logs them, and its `read` never fails), and bytes this task could not
//! hand on. A full receive ring inside embassy's driver drops bytes without a flag; that frame
//! fails its CRC (docs/rig.md, "Line errors").

use defmt::info;
use embassy_futures::select::{select, Either};
use embassy_stm32::usart::BufferedUart;
use embedded_io_async::{Read, Write};
use kapitza_core::link::{BAUD, PROTOCOL_VERSION};

use crate::channels::{FROM_LAPTOP, LINE_ERROR, TO_LAPTOP};

#[embassy_executor::task]
pub async fn run(uart: BufferedUart<'static>) {
    let (mut tx, mut rx) = uart.split();
    let mut inbox = [0u8; 64];
    let mut outbox = [0u8; 64];
    info!("link: protocol v{}, {} baud", PROTOCOL_VERSION, BAUD);
    loop {
        match select(rx.read(&mut inbox), TO_LAPTOP.read(&mut outbox)).await {
            Either::First(Ok(n)) => {
                // A full pipe means the control loop is stalled (the watchdog deals with that);
                // the bytes lost here are a line error, and their frame fails its CRC.
                if FROM_LAPTOP.try_write(&inbox[..n]) != Ok(n) {
                    LINE_ERROR.signal(());
                }
            }
            Either::First(Err(_)) => LINE_ERROR.signal(()),
            Either::Second(n) => {
                // A write error on the ST-LINK's UART leaves nothing to retry: the frame is lost
                // and the host's timeout resends it.
                let _ = tx.write_all(&outbox[..n]).await;
            }
        }
    }
}
