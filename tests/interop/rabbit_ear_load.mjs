// Load a FOLD file with Rabbit Ear (https://rabbitear.org) and check it is a valid graph.
//
//   node rabbit_ear_load.mjs design.fold
//
// Builds ear.graph() from the key frame (the crease pattern) and from every frame of
// file_frames merged over the key frame when it inherits (the folded form); each must have
// vertices, edges and faces with in-range references and pass ear.graph.validate(). Prints a
// JSON summary on stdout; exits 1 (message on stderr) when the file does not load or check.
import fs from "node:fs";
import ear from "rabbit-ear";

function check(graph, name, dims) {
  for (const key of ["vertices_coords", "edges_vertices", "faces_vertices"]) {
    if (!Array.isArray(graph[key]) || graph[key].length === 0) {
      throw new Error(`${name}: no ${key}`);
    }
  }
  const bad = graph.vertices_coords.findIndex((c) => c.length !== dims);
  if (bad >= 0) throw new Error(`${name}: vertex ${bad} has ${graph.vertices_coords[bad].length} coordinates, not ${dims}`);
  const report = ear.graph.validate(graph);
  if (report.summary !== "valid") {
    throw new Error(`${name}: ear.graph.validate says ${JSON.stringify(report)}`);
  }
  return {
    vertices: graph.vertices_coords.length,
    edges: graph.edges_vertices.length,
    faces: graph.faces_vertices.length,
    assignments: [...new Set(graph.edges_assignment ?? [])].sort(),
  };
}

function main(argv) {
  if (argv.length !== 1) throw new Error("usage: node rabbit_ear_load.mjs FILE.fold");
  const fold = JSON.parse(fs.readFileSync(argv[0], "utf8"));
  const { file_frames: frames = [], ...key } = fold;
  const summary = { key: check(ear.graph(structuredClone(key)), "key frame", 2), frames: [] };
  frames.forEach((frame, i) => {
    const merged = frame.frame_inherit ? { ...structuredClone(key), ...frame } : frame;
    const dims = (frame.frame_attributes ?? []).includes("3D") ? 3 : 2;
    summary.frames.push(check(ear.graph(merged), `file_frames[${i}]`, dims));
  });
  return summary;
}

try {
  process.stdout.write(JSON.stringify(main(process.argv.slice(2))) + "\n");
} catch (err) {
  process.stderr.write(`rabbit_ear_load: ${err.message}\n`);
  process.exit(1);
}
