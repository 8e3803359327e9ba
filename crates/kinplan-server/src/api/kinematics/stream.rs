//! StreamIk: one long-lived stream, each message's work admitted on its own.

use super::*;

/// One `StreamIk` call: the first message names the robot and options; every
/// message is one target, solved on the CPU pool from the previous answer.
pub(super) async fn stream_loop(
    mut inbound: Streaming<pb::StreamIkRequest>,
    tx: &tokio::sync::mpsc::Sender<Result<pb::StreamIkResponse, Status>>,
    models: &ModelStore,
    compute: &Compute,
    deadline: Option<Instant>,
) -> Result<(), Status> {
    struct Session {
        chain: Arc<Chain>,
        options: Options,
        previous: Vec<f64>,
        /// The solver's buffers, lent to each solve and handed back (`None` only if a
        /// solve never ran, e.g. its deadline passed in the queue).
        workspace: Option<IkWorkspace>,
    }
    let mut session: Option<Session> = None;
    let idle = compute.stream_idle_timeout;
    loop {
        let Ok(next) = tokio::time::timeout(idle, inbound.message()).await else {
            return Err(Status::unavailable(format!(
                "no message for {} s: the stream was ended; open a new one",
                idle.as_secs_f64()
            )));
        };
        let Some(msg) = next? else { break };
        let seq = msg.sequence;
        let at = |s: Status| with_sequence(s, seq);
        let _admitted = compute.admit_work().map_err(at)?;
        crate::runtime::request_numbers::check_request(&msg).map_err(at)?;
        let mut model_id = Vec::new();
        let st = match session.as_mut() {
            None => {
                let robot = models
                    .resolve(msg.robot.as_ref(), compute, &Budget::new(deadline))
                    .await
                    .map_err(at)?;
                let options = Options::from_proto(msg.options.as_ref(), RESTARTS_WARM).map_err(at)?;
                model_id = robot.model_id.clone();
                session.insert(Session {
                    previous: robot.chain.mid_limits(),
                    workspace: Some(IkWorkspace::new(&robot.chain)),
                    chain: robot.chain,
                    options,
                })
            }
            Some(st) => {
                if msg.robot.is_some() {
                    return Err(at(invalid(
                        "robot",
                        "is set only in the first message of a stream",
                    )));
                }
                if msg.options.is_some() {
                    return Err(at(invalid(
                        "options",
                        "are set only in the first message of a stream",
                    )));
                }
                st
            }
        };
        let target = target_in("target", msg.target.as_ref(), st.options.position_only).map_err(at)?;
        let seed = if msg.seed.is_empty() {
            st.previous.clone()
        } else {
            msg.seed
        };
        let params = st.options.params;
        let chain = st.chain.clone();
        let rng_seed = st.options.rng_seed;
        let workspace = st.workspace.take().unwrap_or_else(|| IkWorkspace::new(&chain));
        let (result, workspace) = compute
            .run(&Budget::new(deadline), move |b| {
                let mut solver = IkSolver::with_workspace(&chain, workspace);
                let result = solver.solve(&target, Some(&seed), &params, rng_seed, b.deadline());
                (result, solver.into_workspace())
            })
            .await?;
        st.workspace = Some(workspace);
        let result = result.map_err(|e| at(ik_error(e, IkAt::Target)))?;
        if let Some(best) = result.best() {
            st.previous.copy_from_slice(&best.joints);
        }
        let mut reply = result_out(result);
        reply.model_id = model_id;
        let answer = pb::StreamIkResponse {
            sequence: seq,
            result: Some(reply),
        };
        if tx.send(Ok(answer)).await.is_err() {
            return Ok(()); // the client went away
        }
    }
    Ok(())
}

/// Says which stream message a status is about, keeping its field details.
pub(super) fn with_sequence(status: Status, sequence: u64) -> Status {
    use tonic_types::StatusExt;
    let details = status.get_error_details();
    let message = format!("{} (stream message with sequence {sequence})", status.message());
    Status::with_error_details(status.code(), message, details)
}
