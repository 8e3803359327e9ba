//! A `StreamIk` session for a control loop: one long-lived bidirectional
//! stream, a target per cycle, each answer warm-started from the previous one
//! on the server.

use std::time::Duration;

use nalgebra::Isometry3;
use tokio::sync::mpsc;
use tokio_stream::wrappers::ReceiverStream;

use crate::convert::pose_to_proto;
use crate::error::{Error, Result};
use crate::ik::{IkAnswer, IkOptions};
use crate::pb::{self, kinematics_service_client::KinematicsServiceClient};
use crate::robot::Robot;

/// Messages that may be queued towards the server before it reads them.
const SEND_QUEUE: usize = 64;

/// An open `StreamIk` session (see [`Robot::ik_stream`]).
///
/// [`IkStream::solve`] sends a target and waits for its answer (lockstep, a
/// controller's cycle); [`IkStream::send`] and [`IkStream::recv`] pipeline.
/// Each answer is awaited at most the client's timeout: a late answer is an
/// error `DEADLINE_EXCEEDED` for that cycle, and `solve` skips answers to
/// earlier targets so the loop stays in step. The session has no overall
/// deadline; dropping it ends the stream.
pub struct IkStream {
    robot: Robot,
    options: pb::IkOptions,
    sender: mpsc::Sender<pb::StreamIkRequest>,
    answers: tonic::Streaming<pb::StreamIkResponse>,
    next_sequence: u64,
    /// Messages sent before the first answer arrived: resent on a new stream
    /// when a replica did not know the cached model hash.
    unanswered_at_start: Option<Vec<pb::StreamIkRequest>>,
    answer_timeout: Duration,
}

impl Robot {
    /// Opens a `StreamIk` session whose first target starts from `seed`
    /// (empty: mid-limits); `options` hold for the whole session (restarts
    /// default to 0 in a stream: a controller stays on its branch).
    pub async fn ik_stream(&self, seed: &[f64], options: &IkOptions) -> Result<IkStream> {
        let (sender, answers) = open(self).await?;
        Ok(IkStream {
            robot: self.clone(),
            options: options.to_proto(),
            sender,
            answers,
            next_sequence: 0,
            unanswered_at_start: Some(vec![pb::StreamIkRequest {
                seed: seed.to_vec(),
                ..Default::default()
            }]),
            answer_timeout: self.client().timeout(),
        })
    }
}

async fn open(
    robot: &Robot,
) -> Result<(
    mpsc::Sender<pb::StreamIkRequest>,
    tonic::Streaming<pb::StreamIkResponse>,
)> {
    let (sender, receiver) = mpsc::channel(SEND_QUEUE);
    let answers = KinematicsServiceClient::new(robot.client().channel())
        .stream_ik(ReceiverStream::new(receiver))
        .await?
        .into_inner();
    Ok((sender, answers))
}

impl IkStream {
    /// Sends a target (tool pose, base frame), returning its sequence number.
    /// `seed` overrides the warm start for this target (empty: the previous answer).
    pub async fn send(&mut self, target: &Isometry3<f64>, seed: &[f64]) -> Result<u64> {
        let sequence = self.next_sequence;
        let mut message = pb::StreamIkRequest {
            sequence,
            target: Some(pose_to_proto(target)),
            seed: seed.to_vec(),
            ..Default::default()
        };
        if let Some(unanswered) = &mut self.unanswered_at_start {
            if sequence == 0 {
                // the session's first message names the robot and options
                let first = &unanswered[0];
                message.robot = Some(self.robot.reference(false));
                message.options = Some(self.options);
                if message.seed.is_empty() {
                    message.seed = first.seed.clone();
                }
                unanswered.clear();
            }
            unanswered.push(message.clone());
        }
        self.sender.send(message).await.map_err(|_| closed())?;
        self.next_sequence += 1;
        Ok(sequence)
    }

    /// The next answer and the sequence number of the target it answers.
    pub async fn recv(&mut self) -> Result<(u64, IkAnswer)> {
        let answer = match tokio::time::timeout(self.answer_timeout, self.answers.message()).await {
            Err(_) => {
                return Err(Error::Status {
                    code: tonic::Code::DeadlineExceeded,
                    message: format!("no StreamIk answer within {:?}", self.answer_timeout),
                });
            }
            Ok(Ok(Some(answer))) => answer,
            Ok(Ok(None)) => return Err(closed()),
            Ok(Err(status)) => return self.reopen_or_fail(status).await,
        };
        if self.unanswered_at_start.take().is_some()
            && let Some(result) = &answer.result
        {
            self.robot.remember(&result.model_id);
        }
        let result = answer.result.ok_or(Error::Reply("result"))?;
        Ok((answer.sequence, IkAnswer::from_proto(result)?))
    }

    /// Sends a target and waits for its answer (answers to earlier targets
    /// that arrive late are skipped).
    pub async fn solve(&mut self, target: &Isometry3<f64>) -> Result<IkAnswer> {
        let sequence = self.send(target, &[]).await?;
        loop {
            let (answered, answer) = self.recv().await?;
            if answered == sequence {
                return Ok(answer);
            }
        }
    }

    /// The stream failed before its first answer because the server did not
    /// hold the cached model hash: reopen with the URDF text and resend.
    async fn reopen_or_fail(&mut self, status: tonic::Status) -> Result<(u64, IkAnswer)> {
        let resend = status.code() == tonic::Code::NotFound && self.robot.sends_model_id();
        let Some(unanswered) = self.unanswered_at_start.as_mut().filter(|_| resend) else {
            return Err(status.into());
        };
        self.robot.forget();
        if let Some(first) = unanswered.iter_mut().find(|m| m.sequence == 0) {
            first.robot = Some(self.robot.reference(true));
        }
        let messages = unanswered.clone();
        let (sender, answers) = open(&self.robot).await?;
        (self.sender, self.answers) = (sender, answers);
        for message in messages {
            self.sender.send(message).await.map_err(|_| closed())?;
        }
        Box::pin(self.recv()).await
    }
}

fn closed() -> Error {
    Error::Status {
        code: tonic::Code::Unavailable,
        message: "the StreamIk stream was closed".into(),
    }
}
