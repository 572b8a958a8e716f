//! The laptop link on USART2 (the ST-LINK's virtual COM port): bytes in, frames out.
//!
//! Framing, decoding, reasons and the version policy are `kapitza_core::link`; the answers come
//! from the control loop's `RigServer`. This task moves bytes:
//!
//! ```text
//! a valid request     → control loop → (response, effect) → the response, seq = the request's;
//!                       effect Telemetry{period}: stream telemetry (period ≥ MIN_TELEMETRY_MS)
//! a bad frame         → Refused(reason), seq = the frame's if its CRC passed, else 0
//! control loop silent → Refused(Busy) after CONTROL_TIMEOUT
//! ```
//! A UART error (overrun, framing, noise) drops the partial frame and counts as a bad frame; the
//! task never stops.

use defmt::{info, warn};
use embassy_futures::select::{select, Either};
use embassy_stm32::usart::{BufferedUart, BufferedUartTx};
use embassy_time::{with_timeout, Duration, Instant, Timer};
use embedded_io_async::{Read, Write};
use kapitza_core::link::frame::{encode, receive_request, Header};
use kapitza_core::link::serve::Effect;
use kapitza_core::link::{
    FrameReader, Reason, Request, Response, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME, PROTOCOL_VERSION,
};

use crate::channels::{FROM_CONTROL, TELEMETRY, TO_CONTROL};

/// The shortest telemetry period: a telemetry frame is ≤ 100 bytes, 8.7 ms at 115200 baud.
const MIN_TELEMETRY_MS: u16 = 20;
/// How long the control loop may take to answer (it answers within one control tick).
const CONTROL_TIMEOUT: Duration = Duration::from_millis(50);

async fn send(tx: &mut BufferedUartTx<'static>, seq: u8, resp: &Response) {
    let mut out = [0u8; MAX_RESPONSE_FRAME];
    match encode(Header::new(seq), resp, &mut out) {
        Ok(n) => {
            if let Err(e) = tx.write_all(&out[..n]).await {
                warn!("link: write failed: {}", e);
            }
        }
        Err(e) => warn!("link: cannot encode: {}", e),
    }
}

/// Asks the control loop and waits for its answer.
async fn ask(req: Request) -> (Response, Effect) {
    // A late answer to an earlier, timed-out question must not be taken for this one.
    while FROM_CONTROL.try_receive().is_ok() {}
    with_timeout(CONTROL_TIMEOUT, async {
        TO_CONTROL.send(req).await;
        FROM_CONTROL.receive().await
    })
    .await
    .unwrap_or((Response::Refused(Reason::Busy), Effect::None))
}

/// The link's own state: frame counters and the telemetry stream.
struct Link {
    frames_ok: u32,
    frames_bad: u32,
    telemetry: Option<Duration>,
    next_telemetry: Instant,
    telemetry_seq: u8,
}

impl Link {
    async fn answer(&mut self, req: Request) -> Response {
        let (mut resp, effect) = ask(req).await;
        if let Effect::Telemetry { period_ms } = effect {
            self.telemetry = (period_ms > 0)
                .then(|| Duration::from_millis(u64::from(period_ms.max(MIN_TELEMETRY_MS))));
            self.next_telemetry = Instant::now();
        }
        if let Response::Status(s) = &mut resp {
            s.counters.frames_ok = self.frames_ok;
            s.counters.frames_bad = self.frames_bad;
        }
        resp
    }
}

#[embassy_executor::task]
pub async fn run(uart: BufferedUart<'static>) {
    let (mut tx, mut rx) = uart.split();
    let mut reader = FrameReader::<MAX_REQUEST_FRAME>::new();
    let mut link = Link {
        frames_ok: 0,
        frames_bad: 0,
        telemetry: None,
        next_telemetry: Instant::now(),
        telemetry_seq: 0,
    };
    let mut buf = [0u8; 64];
    info!(
        "link: protocol v{}, {} baud",
        PROTOCOL_VERSION,
        kapitza_core::link::BAUD
    );
    loop {
        let wake = match link.telemetry {
            Some(_) => link.next_telemetry,
            None => Instant::MAX,
        };
        match select(rx.read(&mut buf), Timer::at(wake)).await {
            Either::First(Ok(n)) => {
                for &b in &buf[..n] {
                    let Some(got) = reader.push(b) else { continue };
                    let (seq, result) = match got {
                        Ok(stuffed) => receive_request(stuffed),
                        Err(reason) => (0, Err(reason)),
                    };
                    let resp = match result {
                        Ok(req) => {
                            link.frames_ok = link.frames_ok.saturating_add(1);
                            link.answer(req).await
                        }
                        Err(reason) => {
                            link.frames_bad = link.frames_bad.saturating_add(1);
                            warn!("link: bad frame: {}", reason);
                            Response::Refused(reason)
                        }
                    };
                    send(&mut tx, seq, &resp).await;
                }
            }
            Either::First(Err(e)) => {
                warn!("link: receive error: {}", e);
                reader.reset();
                link.frames_bad = link.frames_bad.saturating_add(1);
            }
            Either::Second(()) => {
                if let (Some(period), Some(t)) = (link.telemetry, TELEMETRY.try_get()) {
                    link.telemetry_seq = link.telemetry_seq.wrapping_add(1);
                    send(&mut tx, link.telemetry_seq, &Response::Telemetry(t)).await;
                    link.next_telemetry = Instant::now() + period;
                } else {
                    link.next_telemetry = Instant::now() + Duration::from_millis(100);
                }
            }
        }
    }
}
