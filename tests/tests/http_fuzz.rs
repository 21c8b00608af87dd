//! 300 fuzzed case submissions to a real server on loopback (issue 22, item 4; the example
//! `http-fuzz` runs 10,000): no 5xx, no panic, every 4xx a problem document, every 422 naming
//! its fields by JSON pointer, and 10^8 particles refused without the memory to hold them.

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn fuzzed_submissions_are_answered_with_problem_documents() {
    let report = fluidbed_tests::fuzz::run(300, 7).await;
    eprintln!("{}", report.json_line());
    assert_eq!(report.cases, 300);
    assert!(report.clean(), "{:#?}", report.failures);
    assert!(report.by_status.get(&422).is_some_and(|&n| n > 30), "the mutations reach validation: {report:?}");
    assert!(report.accepted > 0, "some mutations stay valid: {report:?}");
    // 10^8 particles would need ~60 GB (600 B each): the whole run stays far below.
    assert!(report.peak_rss_growth_mib < 512.0, "{report:?}");
}
