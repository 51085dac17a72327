// A hadou PNG sequence as a Flamenco 3 job type (docs/farm.md): put this file in the Manager's
// `scripts/` folder. One task per chunk of frames, each one `hadou render` process (Flamenco's
// `exec` command). Not run in CI.
const JOB_TYPE = {
  label: "hadou sequence",
  settings: [
    { key: "scene", type: "string", subtype: "file_path", required: true },
    { key: "output_dir", type: "string", subtype: "dir_path", required: true },
    { key: "frames", type: "string", default: "0-23", required: true },
    { key: "chunk_size", type: "int32", default: 5, propargs: { min: 1 } },
    { key: "width", type: "int32", default: 1280, propargs: { min: 1, max: 16384 } },
    { key: "height", type: "int32", default: 720, propargs: { min: 1, max: 16384 } },
    { key: "samples", type: "int32", default: 4, choices: [1, 4, 9, 16] },
    { key: "backend", type: "string", default: "cpu", choices: ["cpu", "gpu"] },
  ],
};

function compileJob(job) {
  const s = job.settings;
  // frameChunker gives contiguous chunks as "0-4", "5-9", …, or "23": forms `--frames` reads.
  for (const chunk of frameChunker(s.frames, s.chunk_size)) {
    const task = author.Task(`render-${chunk}`, "misc");
    task.addCommand(
      author.Command("exec", {
        exe: "hadou",
        args: [
          "render", s.scene, "-o", s.output_dir + "/", "--frames", chunk,
          "--width", String(s.width), "--height", String(s.height),
          "--samples", String(s.samples), "--backend", s.backend,
          "--skip-existing", "--progress", "none",
        ],
      }),
    );
    job.addTask(task);
  }
}
