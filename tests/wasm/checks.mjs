// SPDX-License-Identifier: MIT
// The node tests' checks: each failing check prints one line, finish() prints "N passed, M
// failed" and exits 1 if any failed. thrown()/thrownAsync() give what a call throws as
// { code, status, message } for the module's CbrdfError (the class of the cbrdf.mjs under test,
// passed in, so that an error of another class never passes for one) or { other: description }.
export function checks(CbrdfError) {
  let passed = 0, failed = 0;
  const describe = (e) => (e instanceof CbrdfError
    ? { code: e.code, status: e.status, message: e.message } : { other: String(e) });
  return {
    check(ok, what) {
      if (ok) {
        ++passed;
      } else {
        ++failed;
        console.log(`FAIL ${what}`);
      }
    },
    thrown(fn) {
      try {
        fn();
      } catch (e) {
        return describe(e);
      }
      return { other: 'nothing thrown' };
    },
    async thrownAsync(fn) {
      try {
        await fn();
      } catch (e) {
        return describe(e);
      }
      return { other: 'nothing thrown' };
    },
    finish() {
      console.log(`${passed} passed, ${failed} failed`);
      process.exit(failed === 0 ? 0 : 1);
    },
  };
}
