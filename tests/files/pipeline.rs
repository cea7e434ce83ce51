//! `parvo::pipeline` used as a library, as an asset pipeline would: a
//! batch in, one outcome per job out; `update` skips outputs that store
//! this run's fingerprint and rebuilds when a setting changes; two jobs
//! with one output are refused; usage errors are found before any input
//! is read.

use std::sync::Mutex;

use parvo::io::OutputKind;
use parvo::pipeline::{self, Job, Settings, Status};
use parvo::{MipFilter, Rounding};

fn run(jobs: &[Job], s: &Settings) -> Vec<(String, Result<Status, String>)> {
    let out = Mutex::new(Vec::new());
    pipeline::run(jobs, s, &mut |_| {}, &|job, r| {
        out.lock().unwrap().push((
            job.input.clone(),
            r.map(|o| o.status).map_err(|e| e.to_string()),
        ));
    });
    let mut v = out.into_inner().unwrap();
    v.sort_by(|a, b| a.0.cmp(&b.0));
    v
}

#[test]
fn a_batch_writes_then_is_up_to_date_then_rebuilds_on_a_new_setting() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = vec![
        "builtin:checker:64".to_string(),
        "builtin:zoneplate:32".to_string(),
    ];
    let jobs = Job::batch(&inputs, dir.path(), OutputKind::KTX2);
    assert_eq!(jobs[0].output, dir.path().join("builtin-checker-64.ktx2"));
    assert!(jobs.iter().all(|j| j.kind == OutputKind::KTX2));
    let mut s = Settings {
        update: true,
        ..Default::default()
    };
    pipeline::check(&jobs, &s).unwrap();
    let first = run(&jobs, &s);
    assert!(
        first.iter().all(|(_, r)| *r == Ok(Status::Written)),
        "{first:?}"
    );
    let second = run(&jobs, &s);
    assert!(
        second.iter().all(|(_, r)| *r == Ok(Status::UpToDate)),
        "{second:?}"
    );
    s.filter = MipFilter::Kaiser;
    let third = run(&jobs, &s);
    assert!(
        third.iter().all(|(_, r)| *r == Ok(Status::Written)),
        "{third:?}"
    );
    s.dry_run = true;
    s.filter = MipFilter::Lanczos3;
    let fourth = run(&jobs, &s);
    assert!(
        fourth.iter().all(|(_, r)| *r == Ok(Status::DryRun)),
        "{fourth:?}"
    );
}

#[test]
fn one_output_for_two_jobs_is_refused_and_usage_errors_come_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("same.exr");
    let jobs = vec![
        Job::new("builtin:checker:16", &out).unwrap(),
        Job::new("builtin:zoneplate:16", &out).unwrap(),
    ];
    let r = run(&jobs, &Settings::default());
    let errors: Vec<&String> = r.iter().filter_map(|(_, r)| r.as_ref().err()).collect();
    assert_eq!(errors.len(), 1, "{r:?}");
    assert!(errors[0].contains("also the output of"), "{}", errors[0]);

    let ktx = vec![Job::new("builtin:checker:16", &dir.path().join("a.ktx2")).unwrap()];
    let up = Settings {
        rounding: Rounding::Up,
        ..Default::default()
    };
    assert!(
        pipeline::check(&ktx, &up)
            .unwrap_err()
            .to_string()
            .contains("floor")
    );
    let zero = Settings {
        levels: Some(0),
        ..Default::default()
    };
    assert!(pipeline::check(&ktx, &zero).is_err());
    assert!(Job::new("x", &dir.path().join("a.bmp")).is_err());
}
