// SPDX-License-Identifier: MIT
// consumer.ts under a bundler's resolution (module esnext, moduleResolution bundler: Vite,
// webpack; the consumer checked, skipLibCheck), then fails unless it uses the whole declared API:
// every export of each entry point ('cbrdf', 'cbrdf/glsl', 'cbrdf/three'), every member of the
// exported classes and every method of the exported interfaces (an instance's API), so that no
// declaration goes unchecked. One program for both: a second tsc run would parse it all again.
//   usage: node coverage.mjs WORK   (WORK as types_test.sh leaves it: tsconfig.json, consumer.ts)
import { createRequire } from 'node:module';
import path from 'node:path';

const work = path.resolve(process.argv[2] ?? '.');
const ts = createRequire(import.meta.url)('typescript');  // this folder's, pinned
const entries = ['cbrdf', 'cbrdf/glsl', 'cbrdf/three'];

const config = ts.getParsedCommandLineOfConfigFile(path.join(work, 'tsconfig.json'), {}, {
  ...ts.sys, onUnRecoverableConfigFileDiagnostic: (d) => { throw new Error(String(d.messageText)); },
});
const options = { ...config.options, module: ts.ModuleKind.ESNext,
                  moduleResolution: ts.ModuleResolutionKind.Bundler, skipLibCheck: true };
const program = ts.createProgram(config.fileNames, options);
const diagnostics = ts.getPreEmitDiagnostics(program);
if (diagnostics.length) {
  console.error(ts.formatDiagnostics(diagnostics, {
    getCanonicalFileName: (f) => f, getCurrentDirectory: () => work, getNewLine: () => '\n' }));
  console.error('coverage: errors under module esnext, moduleResolution bundler');
  process.exit(1);
}
console.log('coverage: module esnext, moduleResolution bundler, skipLibCheck: no errors');
const checker = program.getTypeChecker();
const consumer = program.getSourceFile(path.join(work, 'consumer.ts'));
if (!consumer) throw new Error(`coverage: no consumer.ts in ${work}`);

const resolve = (s) => (s && s.flags & ts.SymbolFlags.Alias ? checker.getAliasedSymbol(s) : s);
// Every symbol the consumer names, aliases resolved; and the members reached through a type.
const used = new Set();
const imported = new Map(entries.map((e) => [e, new Set()]));
const moduleSymbols = new Map();
ts.forEachChild(consumer, function visit(node) {
  if (ts.isImportDeclaration(node) && imported.has(node.moduleSpecifier.text)) {
    moduleSymbols.set(node.moduleSpecifier.text, checker.getSymbolAtLocation(node.moduleSpecifier));
    for (const e of node.importClause?.namedBindings?.elements ?? []) {
      imported.get(node.moduleSpecifier.text).add((e.propertyName ?? e.name).text);
    }
  }
  if (ts.isIdentifier(node) || ts.isPrivateIdentifier(node)) {
    const s = checker.getSymbolAtLocation(node);
    if (s) {
      used.add(s);
      used.add(resolve(s));
    }
  }
  ts.forEachChild(node, visit);
});

const missing = [];
const inPackage = (decl) => /[\\/]node_modules[\\/]cbrdf[\\/]/.test(decl.getSourceFile().fileName);
for (const entry of entries) {
  const mod = moduleSymbols.get(entry);
  if (!mod) {
    missing.push(`${entry}: not imported`);
    continue;
  }
  for (const exp of checker.getExportsOfModule(mod)) {
    if (!imported.get(entry).has(exp.name)) missing.push(`${entry}: ${exp.name} not imported`);
    const target = resolve(exp);
    const decls = (target.declarations ?? []).filter(inPackage);
    const isClass = decls.some(ts.isClassDeclaration);
    const isInterface = decls.some(ts.isInterfaceDeclaration);
    if (!isClass && !isInterface) continue;
    for (const member of checker.getPropertiesOfType(checker.getDeclaredTypeOfSymbol(target))) {
      const mdecls = (member.declarations ?? []).filter(inPackage);
      if (mdecls.length === 0) continue;  // inherited from three or the DOM
      const callable = mdecls.some((d) => ts.isMethodDeclaration(d) || ts.isMethodSignature(d) ||
                                          ts.isGetAccessor(d) || ts.isSetAccessor(d));
      // Classes: every member; interfaces: their methods (data fields are used as data).
      if (!(isClass || callable)) continue;
      if (!used.has(member)) missing.push(`${entry}: ${exp.name}.${member.name} not used`);
    }
  }
}
if (missing.length) {
  console.error(`coverage: consumer.ts does not use all of the declared API:\n  ${missing.join('\n  ')}`);
  process.exit(1);
}
console.log(`coverage: consumer.ts imports every export of ${entries.join(', ')} and uses every ` +
            'method of their classes and instance interfaces');
