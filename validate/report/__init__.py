"""Reports that people and CI servers read: JUnit XML of a suite run, and self-contained HTML pages.

A page (:mod:`.page`) is built from small sections (:mod:`.sections`), each rendering its own HTML
fragment, the way MuJoCo's system-identification report is built: a command collects its sections
and writes the page whole. The pages of this project: a suite run (:mod:`.suite_page`,
``validate all --html``), an identification (:mod:`.identify_page`, ``identify --html``) and a sweep
(:mod:`.sweep_page`, ``sweep --out DIR`` writes ``DIR/report.html``). Every page opens from a file
with no network: the style is inline and every figure is a PNG inside the page (a ``data:`` URI).
"""
