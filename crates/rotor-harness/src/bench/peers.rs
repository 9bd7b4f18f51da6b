//! Which of the repository's peers ([`crate::protocol::peers`]) a benchmark runs, each with
//! its ladder: those the options turn on and whose interpreter can run them; the others are
//! reported as skipped, with the reason.

use crate::bench::clients::{ClientReport, ClientStatus};
use crate::bench::options::{BenchOptions, PeerOptions};
use crate::protocol::ClientSpec;
use crate::protocol::peers::{PEERS, Peer};

/// A peer to run: its client spec and ladder, or the report of a peer that is skipped.
pub(crate) type PeerLaunch = Result<(ClientSpec, Vec<f64>), Box<ClientReport>>;

/// Whether the options turn a peer on, the interpreter that runs it, and its ladder. The
/// scipy methods other than DOP853 run with scipy, on their own ladder (none: not run).
fn setting<'a>(p: &'a PeerOptions, peer: &Peer) -> (bool, &'a str, &'a [f64]) {
    match peer.name {
        "scipy" => (p.scipy, &p.python, &p.scipy_tols),
        "siconos" => (p.siconos, &p.siconos_python, &p.siconos_hs),
        "octave" => (p.octave, &p.octave_cli, &p.octave_tols),
        // scipy-radau, scipy-bdf, scipy-lsoda
        _ => (
            p.scipy && !p.scipy_method_tols.is_empty(),
            &p.python,
            &p.scipy_method_tols,
        ),
    }
}

/// The peers the options ask for, each with its ladder, or skipped with the reason.
pub(crate) fn peers(opts: &BenchOptions, progress: &mut impl FnMut(&str)) -> Vec<PeerLaunch> {
    let p = &opts.peers;
    PEERS
        .iter()
        .map(|peer| {
            let (on, program, ladder) = setting(p, peer);
            let spec = peer.spec(program, &p.dir);
            let skip = |why: String| {
                Err(Box::new(ClientReport::skipped(
                    &spec,
                    ClientStatus::Skipped,
                    why,
                )))
            };
            if !on {
                return skip("turned off in the options".into());
            }
            if let Err(why) = peer.available(program) {
                progress(&format!("{} peer skipped: {why}", peer.name));
                return skip(why);
            }
            Ok((spec.clone(), ladder.to_vec()))
        })
        .collect()
}
